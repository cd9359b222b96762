// A library that exports nlobs_plugin_info by hand, as a plugin built against something else
// would: compiled once per defect (FOREIGN_MAGIC, FOREIGN_LAYOUT, FOREIGN_VERSION, FOREIGN_ABI,
// NULL_INFO). The loader must refuse each, naming it, before it calls its registration.
#include <stdexcept>

#include "nlobs/registry/plugin.hpp"

#if !defined(NULL_INFO)
namespace {

void must_not_run(nlobs::PluginRegistrar&) {
  throw std::logic_error("the loader called the registration of a refused plugin");
}

}  // namespace
#endif

extern "C" __attribute__((visibility("default"))) const nlobs::PluginInfo* nlobs_plugin_info() {
#if defined(NULL_INFO)
  return nullptr;
#else
  static const nlobs::PluginInfo info {
#if defined(FOREIGN_MAGIC)
    0x12345678u,
#else
    nlobs::kPluginMagic,
#endif
#if defined(FOREIGN_LAYOUT)
        nlobs::kPluginLayout + 1,
#else
        nlobs::kPluginLayout,
#endif
#if defined(FOREIGN_VERSION)
        "0.0.9",
#else
        NLOBS_VERSION_STRING,
#endif
#if defined(FOREIGN_ABI)
        "libc++ abi=1",
#else
        NLOBS_PLUGIN_ABI_TAG,
#endif
        &must_not_run
  };
  return &info;
#endif
}
