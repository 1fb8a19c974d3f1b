#include "app/cli.h"
#include "app/omp_wait_policy.h"

int main(int argc, char** argv) {
    sahara::restart_with_passive_wait(argv);
    return sahara::run_cli(argc, argv);
}
