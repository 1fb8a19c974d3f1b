#include "app/cli.h"

#include <cstdio>

namespace sahara {

int run_cli(int, char**) {
    std::printf("sahara %s\n", SAHARA_VERSION);
    return 0;
}

}  // namespace sahara
