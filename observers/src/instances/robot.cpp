// The observer the CLI builds for FlexibleJointRobot, compiled once (its header declares it
// extern).
#include "nlobs/observers/mvt/mvt_observer.hpp"

namespace nlobs {

static_assert(FlexibleJointRobot::kOutputs != 1 || FlexibleJointRobot::kInputs != 0,
              "an autonomous one-output model belongs in catalogue.hpp's high-gain list");

template class MvtObserver<FlexibleJointRobot>;

}  // namespace nlobs
