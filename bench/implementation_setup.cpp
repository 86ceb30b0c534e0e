#include "implementation_setup.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave::bench {

SolverKind solver_of(Implementation implementation) {
  switch (implementation) {
    case Implementation::cleave:
    case Implementation::paper: return SolverKind::multigrid_cg;
    case Implementation::eigen_cg: return SolverKind::eigen_cg;
    case Implementation::cholmod: return SolverKind::cholmod;
  }
  return SolverKind::multigrid_cg;
}

ImplementationScope::ImplementationScope(Implementation implementation)
    : solver_(solver_of(implementation)), parallel_substitution_(implementation != Implementation::cholmod) {
  if (implementation == Implementation::paper)
    one_thread_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
}

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size())
    throw InputError(fmt::format("comparing results of {} and {} values; expected equal sizes", a.size(), b.size()));
  const double reference = b.norm();
  const double difference = (a - b).norm();
  if (reference == 0) return difference == 0 ? 0.0 : 1.0;
  return difference / reference;
}

}  // namespace cleave::bench
