#include "app/cli.h"

int main(int argc, char** argv) { return sahara::run_cli(argc, argv); }
