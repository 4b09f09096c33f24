// animat_evolve's entry point: the command line is animat_evolve_main() (animat_evolve.cpp).
int animat_evolve_main(int argc, char** argv);

int main(int argc, char** argv) { return animat_evolve_main(argc, argv); }
