#pragma once
// Front door of the model layer: what a model is (ModelSizes, the two concepts), the fixed-step
// discretisation of a continuous model, and the shipped systems. The adaptive (Boost.Odeint)
// discretisation has its own header, nlobs/models/odeint_discretization.hpp.
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/systems.hpp"
