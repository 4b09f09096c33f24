// The MPI evaluator in a build without MPI: every use says how to get it.
#include <cstdlib>

#include "animat/evaluator.hpp"
#include "animat/mpi.hpp"

namespace animat::mpi {

bool built_with_mpi() { return false; }

struct Job::State {};

Job::Job(int&, char**&) { throw Error(how_to_get_mpi()); }
Job::~Job() = default;
int Job::rank() const { return 0; }
int Job::size() const { return 1; }
int Job::serve() { throw Error(how_to_get_mpi()); }
std::shared_ptr<Evaluator> Job::start(const Config&, const std::atomic<bool>*) {
  throw Error(how_to_get_mpi());
}
void Job::abandon(int status) { std::_Exit(status); }

}  // namespace animat::mpi
