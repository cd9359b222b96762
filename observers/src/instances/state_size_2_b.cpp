// One unit of the catalogue's observer instances (the files included below, one per model):
// grouped by state size, which the models' observers share most of (the fixed-size Eigen types
// of the Taylor maps' orders, the high-gain and MVT machinery). observers/CMakeLists.txt says why.
#include "lti_injection.inc"
#include "pendulum.inc"
#include "unknown_input.inc"
