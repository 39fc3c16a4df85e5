// Pose files of Tejani et al. 2014 (ECCV, "Latent-class Hough forests"): a count, then 4x4
// object-to-camera matrices in metres. Read token by token so every error names its line.
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "eval/checks.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

struct Token {
  std::string text;
  int line = 0;
};

std::vector<Token> tokens(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the pose file", path));
  std::vector<Token> out;
  std::string line_text;
  for (int line = 1; std::getline(in, line_text); ++line) {
    std::istringstream words(line_text);
    for (std::string w; words >> w;) out.push_back({w, line});
  }
  return out;
}

double finiteNumber(const Token& tok, const std::string& path) {
  double v = 0;
  const char* end = tok.text.data() + tok.text.size();
  const auto [ptr, ec] = std::from_chars(tok.text.data(), end, v);
  if (ec != std::errc() || ptr != end)
    throw InputError(fmt::format("{}: line {}: '{}' is not a number", path, tok.line, tok.text));
  if (!std::isfinite(v))
    throw InputError(fmt::format("{}: line {}: '{}' is not a finite number", path, tok.line, tok.text));
  return v;
}

}  // namespace

std::vector<Pose> loadTejaniPoses(const std::string& path) {
  const auto toks = tokens(path);
  if (toks.empty()) throw InputError(fmt::format("{}: empty file, expected the number of poses on line 1", path));
  const Token& head = toks[0];
  int count = -1;
  {
    const char* end = head.text.data() + head.text.size();
    const auto [ptr, ec] = std::from_chars(head.text.data(), end, count);
    if (ec != std::errc() || ptr != end || count < 0)
      throw InputError(fmt::format("{}: line {}: '{}' is not a number of poses", path, head.line, head.text));
  }
  std::vector<double> values;
  values.reserve(toks.size() - 1);
  for (std::size_t i = 1; i < toks.size(); ++i) values.push_back(finiteNumber(toks[i], path));

  const std::size_t needed = static_cast<std::size_t>(count) * 16;
  if (values.size() < needed)
    throw InputError(fmt::format("{}: line {} says {} poses, but the file ends at line {} after {} complete {}{}", path,
                                 head.line, count, toks.back().line, values.size() / 16,
                                 values.size() / 16 == 1 ? "matrix" : "matrices",
                                 values.size() % 16 ? fmt::format(" and {} more numbers", values.size() % 16) : ""));
  if (values.size() > needed)
    throw InputError(fmt::format("{}: line {} says {} poses, but more numbers follow from line {}", path, head.line,
                                 count, toks[1 + needed].line));

  std::vector<Pose> poses;
  for (int p = 0; p < count; ++p) {
    const double* m = values.data() + 16 * p;
    const int first = toks[1 + 16 * p].line, last = toks[16 + 16 * p].line;
    const auto where = [&] { return fmt::format("{}: lines {}-{} (pose {})", path, first, last, p); };
    if (std::abs(m[12]) > 1e-6 || std::abs(m[13]) > 1e-6 || std::abs(m[14]) > 1e-6 || std::abs(m[15] - 1) > 1e-6)
      throw InputError(
          fmt::format("{}: the last row is {} {} {} {}, not 0 0 0 1", where(), m[12], m[13], m[14], m[15]));
    Eigen::Matrix3d R;
    R << m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10];
    if (const auto problem = eval::rotationProblem(R)) throw InputError(fmt::format("{}: {}", where(), *problem));
    Pose pose;
    pose.R = R.cast<float>();
    pose.t = Eigen::Vector3d(m[3], m[7], m[11]).cast<float>();
    poses.push_back(pose);
  }
  return poses;
}

}  // namespace vkpose
