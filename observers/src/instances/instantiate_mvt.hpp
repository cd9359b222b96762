#pragma once
// The explicit instantiations of the observers the CLI builds for one catalogue model
// (nlobs/models/catalogue.hpp), for the units of this folder, one per state size; the observers'
// headers declare them extern.
#include "nlobs/observers/mvt/mvt_observer.hpp"

// A model outside the high-gain list (inputs, or several outputs): its MVT observer.
#define NLOBS_INSTANTIATE_MVT_MODEL(M)                                                       \
  static_assert(M::kOutputs != 1 || M::kInputs != 0,                                         \
                "an autonomous one-output model belongs in catalogue.hpp's high-gain list"); \
  template class MvtObserver<M>;
