// `animat evolve` runs the very command line of animat_evolve (src/cli/animat_evolve.cpp) in the
// Python process: compiled here without its main(), called by animat._core.evolve_cli.
#define ANIMAT_CLI_NO_MAIN
#include "../src/cli/animat_evolve.cpp"
