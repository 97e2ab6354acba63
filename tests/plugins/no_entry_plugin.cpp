// A shared library that is not a gpilqg plugin: it has no entry points.
extern "C" __attribute__((visibility("default"))) int not_a_gpilqg_plugin() { return 1; }
