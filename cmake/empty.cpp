// Empty: the layer checks of CMakeLists.txt link whole archives into a shared library.
