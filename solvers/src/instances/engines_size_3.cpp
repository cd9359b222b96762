#define NLOBS_INSTANCE_SIZE 3
#include "engines_at_size.inc"
