#pragma once
// The core of the solver layer in one include. The Ceres and NLopt engines and the registry
// that knows them by name are separate includes (they pull in Ceres' and NLopt's headers):
//   nlobs/solvers/ceres_engine.hpp, nlobs/solvers/nlopt_engine.hpp,
//   nlobs/solvers/engine_registry.hpp
#include "nlobs/solvers/accelerated_engine.hpp"
#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/broyden_engine.hpp"
#include "nlobs/solvers/contraction.hpp"
#include "nlobs/solvers/dogleg_engine.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/finite_difference.hpp"
#include "nlobs/solvers/fixed_point_engines.hpp"
#include "nlobs/solvers/levenberg_marquardt_engine.hpp"
#include "nlobs/solvers/newton_engine.hpp"
#include "nlobs/solvers/objective_problem.hpp"
#include "nlobs/solvers/polyalgorithm_engine.hpp"
#include "nlobs/solvers/problem.hpp"
#include "nlobs/solvers/pseudo_transient_engine.hpp"
#include "nlobs/solvers/root_adapter.hpp"
#include "nlobs/solvers/spectral_radius.hpp"
#include "nlobs/solvers/status.hpp"
#include "nlobs/solvers/stop_criteria.hpp"
#include "nlobs/solvers/summary.hpp"
#include "nlobs/solvers/types.hpp"
