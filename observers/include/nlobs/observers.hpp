#pragma once
// Front door of the observer layer: the Observer interface and the harness (simulate,
// run_observers), the window estimators (any engine × any output window), the baselines
// (Luenberger, sliding mode, EKF) and the observers of the source papers (MVT, PI bank,
// modulating-function, high-gain). Each family's own header is lighter where compile time
// matters (docs/observers.md lists them).
#include "nlobs/models.hpp"
#include "nlobs/observers/baselines/baselines.hpp"
#include "nlobs/observers/baselines/finite_difference_observer.hpp"
#include "nlobs/observers/baselines/unscented_kalman_filter.hpp"
#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/core/observer.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/mhe/mhe_estimator.hpp"
#include "nlobs/observers/modulating/modulating_function_observer.hpp"
#include "nlobs/observers/mvt/mvt_observer.hpp"
#include "nlobs/observers/pi/pi_bank.hpp"
#include "nlobs/observers/window/output_window.hpp"
#include "nlobs/observers/window/window_estimator.hpp"
#include "nlobs/solvers.hpp"
