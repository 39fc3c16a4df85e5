#pragma once
// libFuzzer targets of vkpose's file readers. The readers take paths, so each input is
// written to a file of this process first; a reader may throw vkpose::InputError (a clear
// error is the right answer to garbage), anything else (another exception, a crash, a
// sanitizer report, a hang) is a bug.
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include <unistd.h>

#include "vkpose/error.hpp"

namespace vkpose::fuzz {

/// Writes the input to a per-process file named `name` and returns its path.
inline std::string inputFile(const uint8_t* data, std::size_t size, const std::string& name) {
  const std::string path = "/tmp/vkpose_fuzz_" + std::to_string(::getpid()) + "_" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

/// Runs `read`, accepting an InputError as the answer.
template <class F>
void expectNoCrash(F&& read) {
  try {
    read();
  } catch (const vkpose::InputError&) {
  }
}

}  // namespace vkpose::fuzz
