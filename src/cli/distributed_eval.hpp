#pragma once
// `vkpose eval --workers N` and `--dask ADDRESS`: the run goes to the Python module
// vkpose.distributed (Dask) and comes back as the report one process would have made.
#include <string>

#include "vkpose/evaluation.hpp"

namespace vkpose::cli {

/// Where the run goes: `workers` processes of a cluster on this machine, or the scheduler at
/// `scheduler`; `batch` images per task (0: vkpose.distributed's default).
struct DaskTarget {
  int workers = 0;
  std::string scheduler;
  int batch = 0;
  int connect_timeout_s = 30;  ///< how long to wait for the scheduler
};

/// Runs the job on Dask through `python3 -m vkpose.distributed` and reads its report back.
/// InputError with the Python side's message when it fails (no Dask, no scheduler, a bad bank).
EvalReport runOnDask(const EvalJob& job, const DaskTarget& target, bool quiet);

}  // namespace vkpose::cli
