// What does not need MPI itself: detecting a launch, the thread split, the install hint.
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "animat/mpi.hpp"

namespace animat::mpi {

namespace {
int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  if (!v || !*v) return fallback;
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  return (end && *end == '\0' && x >= 0 && x < 1000000000) ? static_cast<int>(x) : fallback;
}
}  // namespace

Launch detect_launch() {
  Launch l;
  // Open MPI (mpirun/mpiexec), MPICH and Intel MPI (Hydra), Slurm srun with PMI-2 or PMIx.
  static constexpr const char* kSize[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"};
  static constexpr const char* kRank[] = {"OMPI_COMM_WORLD_RANK", "PMI_RANK"};
  for (std::size_t i = 0; i < std::size(kSize); ++i)
    if (const char* v = std::getenv(kSize[i])) {
      l.launched = true;
      l.size = std::max(1, env_int(kSize[i], 1));
      l.rank = env_int(kRank[i], 0);
      l.variable = std::string(kSize[i]) + "=" + v;
      return l;
    }
  if (const char* v = std::getenv("PMIX_RANK")) {
    l.launched = true;
    l.rank = env_int("PMIX_RANK", 0);
    l.size = std::max(1, env_int("SLURM_STEP_NUM_TASKS", env_int("SLURM_NTASKS", 1)));
    l.variable = std::string("PMIX_RANK=") + v;
  }
  return l;
}

std::string how_to_get_mpi() {
  return "this animat_evolve was built without MPI. Install Open MPI (Debian: apt-get install "
         "libopenmpi-dev "
         "openmpi-bin; scripts/setup.sh does) and rebuild (scripts/build.sh, or cmake "
         "-DANIMAT_WITH_MPI=ON)";
}

int threads_per_rank(int requested, int local_ranks) {
  if (requested > 0) return requested;
  const int allowed = omp_get_num_procs();  // this process's affinity mask
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  // bound by the launcher: its cores are ours
  if (online > 0 && allowed < online) return std::max(1, allowed);
  return std::max(1, allowed / std::max(1, local_ranks));
}

}  // namespace animat::mpi
