#pragma once
// Front door of the model layer: what a model is (ModelSizes, the two concepts), the fixed-step
// discretisation of a continuous model, the shipped systems and their hand-derived forms (the
// embeddings q_N of the high-gain observer, the canonical forms of the modulating-function
// observer). The adaptive (Boost.Odeint) discretisation has its own header,
// nlobs/models/odeint_discretization.hpp.
#include "nlobs/models/discretization.hpp"
#include "nlobs/models/embedded_forms.hpp"
#include "nlobs/models/model.hpp"
#include "nlobs/models/modified_chua.hpp"
#include "nlobs/models/modulating_forms.hpp"
#include "nlobs/models/systems.hpp"
