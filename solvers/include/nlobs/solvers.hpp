#pragma once
// Front door of the solver layer: problems, every engine of our own, stop criteria, Summary and
// the engine registry. The engines that wrap other libraries have their own headers
// (nlobs/solvers/ceres_engine.hpp, nlobs/solvers/nlopt_engine.hpp): they cost compile time;
// through the registry ("ceres", "nlopt") they need none.
#include "nlobs/solvers/engine_registry.hpp"
#include "nlobs/solvers/solvers.hpp"
