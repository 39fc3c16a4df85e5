// Runs `python3 -m vkpose.distributed` with the job in a file of a temporary folder, and reads
// the report (or the error) it leaves there. The Python is the one the module was built for;
// VKPOSE_PYTHON names another.
#include "cli/distributed_eval.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "vkpose/error.hpp"

extern char** environ;

namespace vkpose::cli {
namespace fs = std::filesystem;

namespace {

std::string pythonExecutable() {
  if (const char* p = std::getenv("VKPOSE_PYTHON"); p && *p) return p;
#ifdef VKPOSE_PYTHON_EXECUTABLE
  if (fs::exists(VKPOSE_PYTHON_EXECUTABLE)) return VKPOSE_PYTHON_EXECUTABLE;
#endif
  return "python3";
}

/// This environment with the build's Python package first on PYTHONPATH (when built with it).
std::vector<std::string> childEnvironment() {
  std::string package_dir;
#ifdef VKPOSE_PYTHON_PACKAGE_DIR
  if (fs::is_directory(VKPOSE_PYTHON_PACKAGE_DIR)) package_dir = VKPOSE_PYTHON_PACKAGE_DIR;
#endif
  std::vector<std::string> env;
  std::string python_path = package_dir;
  for (char** e = environ; *e; ++e) {
    const std::string entry = *e;
    if (entry.rfind("PYTHONPATH=", 0) == 0) {
      const std::string old = entry.substr(std::strlen("PYTHONPATH="));
      if (!old.empty()) python_path += (python_path.empty() ? "" : ":") + old;
    } else {
      env.push_back(entry);
    }
  }
  if (!python_path.empty()) env.push_back("PYTHONPATH=" + python_path);
  return env;
}

/// A folder of its own under the system's temporary folder, removed with everything in it.
class TempFolder {
 public:
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "vkpose-eval-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw InputError(fmt::format("cannot make a temporary folder: {}", std::strerror(errno)));
    path_ = pattern;
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Runs the command (a PATH search for args[0]) and returns its exit status (-1: no such
/// program).
int runChild(const std::vector<std::string>& args, const std::vector<std::string>& env) {
  std::vector<char*> argv, envp;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  for (const auto& e : env) envp.push_back(const_cast<char*>(e.c_str()));
  argv.push_back(nullptr);
  envp.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), envp.data()) != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

EvalReport runOnDask(const EvalJob& job, const DaskTarget& target, bool quiet) {
  const TempFolder folder;
  {
    std::ofstream out(folder / "job.json");
    out << evalJobJson(job);
    if (!out) throw InputError("cannot write the job file into the temporary folder");
  }
  std::vector<std::string> args = {pythonExecutable(), "-m", "vkpose.distributed",
                                   "--job", (folder / "job.json").string(),
                                   "--result", (folder / "report.json").string(),
                                   "--error", (folder / "error.txt").string()};
  if (!target.scheduler.empty()) {
    args.insert(args.end(), {"--scheduler", target.scheduler, "--connect-timeout",
                             std::to_string(target.connect_timeout_s) + "s"});
  } else {
    args.insert(args.end(), {"--workers", std::to_string(target.workers)});
  }
  if (target.batch > 0) args.insert(args.end(), {"--batch", std::to_string(target.batch)});
  if (quiet) args.emplace_back("--quiet");
  const int status = runChild(args, childEnvironment());
  if (status == -1)
    throw InputError(fmt::format("--workers/--dask run vkpose.distributed with Python, and {} could not be started "
                                 "(VKPOSE_PYTHON names another Python)",
                                 args[0]));
  if (status != 0) {
    std::string message = fs::exists(folder / "error.txt") ? readAll(folder / "error.txt") : std::string();
    if (message.empty())
      message = fmt::format("{} -m vkpose.distributed ended with status {} (is the vkpose Python module built and "
                            "Dask installed? scripts/install-deps.sh installs python3-distributed)",
                            args[0], status);
    throw InputError(message);
  }
  return parseEvalReportState(readAll(folder / "report.json"));
}

}  // namespace vkpose::cli
