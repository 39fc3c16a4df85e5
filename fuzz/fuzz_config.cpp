// libFuzzer target: the stage parameter file of `--config` (parseConfig, src/pipeline/config_io.cpp;
// loadConfig reads the file and hands its text to parseConfig, so the text is fuzzed directly).
// A file that parses is also merged with a command line's value, as the CLI does, and must
// read back as it prints: what `vkpose config --print-defaults` writes, vkpose reads.
#include <cstdlib>
#include <cstdio>
#include <string>

#include "fuzz/fuzz_support.hpp"
#include "vkpose/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  vkpose::fuzz::expectNoCrash([&] {
    const vkpose::DetectorParams defaults;
    const vkpose::DetectorParams from_file = vkpose::parseConfig(text, "fuzz.json", defaults);
    vkpose::DetectorParams flags = defaults;
    flags.match.threshold = 90.f;  // one flag given, so mergeConfig assigns something
    vkpose::mergeConfig(defaults, from_file, flags);
    vkpose::configTable(from_file);
    const std::string printed = vkpose::configJson(from_file);
    std::string reprinted;
    try {
      reprinted = vkpose::configJson(vkpose::parseConfig(printed, "printed.json", defaults));
    } catch (const vkpose::InputError& e) {
      std::fprintf(stderr, "the printed config does not read back: %s\n%s", e.what(), printed.c_str());
      std::abort();
    }
    if (reprinted != printed) {
      std::fprintf(stderr, "the printed config reads back different:\n%s---\n%s", printed.c_str(), reprinted.c_str());
      std::abort();
    }
  });
  return 0;
}
