#include <cerrno>
#include <cstdio>
#include <cstring>

#include "app/cli.h"

int main(int argc, char** argv) {
    const int code = sahara::run_cli(argc, argv);
    // Output lost to a full disk must not pass for success: `info --json > f`
    // would leave a cut-off file behind exit code 0.
    errno = 0;
    const bool flushed = std::fflush(stdout) == 0;
    if (!flushed || std::ferror(stdout)) {
        std::fprintf(stderr, "sahara: error: cannot write to standard output%s%s\n", errno ? ": " : "",
                     errno ? std::strerror(errno) : "");
        return code == 0 ? 2 : code;
    }
    return code;
}
