// A shared library that is not an nlobs plugin: it exports no nlobs_plugin_info.
extern "C" __attribute__((visibility("default"))) int not_a_plugin_answer() {
  return 42;
}
