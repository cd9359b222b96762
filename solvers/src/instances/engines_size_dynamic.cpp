#define NLOBS_INSTANCE_SIZE -1  // nlobs::Dynamic
#include "engines_at_size.inc"
