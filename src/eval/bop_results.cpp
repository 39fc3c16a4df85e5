// bop_toolkit's results CSV ("bop19": bop_toolkit_lib/inout.py, docs/bop_challenge_2019.md).
// R and the score are written as the shortest text that reads back as the same float; t is
// written in millimetres as the shortest text of the exact double 1000 * t, so dividing by 1000
// on reading gives the same float back.
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>

#include "eval/checks.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"

namespace vkpose {
namespace {

constexpr const char* kHeader = "scene_id,im_id,obj_id,score,R,t,time";

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

template <typename T>
T parse(const std::string& text, const std::string& where, const char* column) {
  T v{};
  const std::string s = trimmed(text);
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, v);
  if (s.empty() || ec != std::errc() || ptr != end)
    throw InputError(fmt::format("{}: column '{}': '{}' is not a number", where, column, text));
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(v)) throw InputError(fmt::format("{}: column '{}': '{}' is not finite", where, column, text));
  } else {
    if (v < 0) throw InputError(fmt::format("{}: column '{}': {} must not be negative", where, column, v));
  }
  return v;
}

template <typename T>
std::vector<T> parseList(const std::string& text, std::size_t count, const std::string& where, const char* column) {
  std::istringstream words(text);
  std::vector<T> out;
  for (std::string w; words >> w;) out.push_back(parse<T>(w, where, column));
  if (out.size() != count)
    throw InputError(fmt::format("{}: column '{}' holds {} numbers, expected {}", where, column, out.size(), count));
  return out;
}

}  // namespace

void saveBopResults(const std::string& path, const std::vector<BopResult>& results) {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("{}: cannot write the results file", path));
  out << kHeader << '\n';
  for (const auto& r : results) {
    const auto& e = r.estimate;
    const Eigen::Matrix3f& R = e.R;
    const Eigen::Vector3d t_mm = e.t.cast<double>() * 1000.0;  // exact: a float times 1000 fits a double
    out << fmt::format("{},{},{},{},{} {} {} {} {} {} {} {} {},{} {} {},{}\n", r.scene_id, r.im_id, e.obj_id, e.score,
                       R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2), t_mm.x(),
                       t_mm.y(), t_mm.z(), r.time_s);
  }
  if (!out) throw InputError(fmt::format("{}: writing the results file failed", path));
}

std::vector<BopResult> loadBopResults(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the results file", path));
  std::vector<BopResult> out;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (line_no == 1 && line.find(kHeader) != std::string::npos) continue;
    if (trimmed(line).empty()) continue;
    const std::string where = fmt::format("{}: line {}", path, line_no);
    std::vector<std::string> cols;
    std::istringstream fields(line);
    for (std::string c; std::getline(fields, c, ',');) cols.push_back(c);
    if (!line.empty() && line.back() == ',') cols.emplace_back();
    if (cols.size() != 7)
      throw InputError(fmt::format("{}: {} comma-separated columns, expected 7 ({})", where, cols.size(), kHeader));
    BopResult r;
    r.scene_id = parse<int>(cols[0], where, "scene_id");
    r.im_id = parse<int>(cols[1], where, "im_id");
    r.estimate.obj_id = parse<int>(cols[2], where, "obj_id");
    r.estimate.score = parse<float>(cols[3], where, "score");
    const auto R = parseList<float>(cols[4], 9, where, "R");
    const auto t = parseList<double>(cols[5], 3, where, "t");
    r.time_s = parse<double>(cols[6], where, "time");
    r.estimate.R = Eigen::Map<const Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(R.data());
    if (const auto problem = eval::rotationProblem(r.estimate.R.cast<double>()))
      throw InputError(fmt::format("{}: column 'R': {}", where, *problem));
    for (int a = 0; a < 3; ++a) r.estimate.t[a] = static_cast<float>(t[static_cast<std::size_t>(a)] / 1000.0);
    out.push_back(r);
  }
  return out;
}

}  // namespace vkpose
