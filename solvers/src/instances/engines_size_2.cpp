#define NLOBS_INSTANCE_SIZE 2
#include "engines_at_size.inc"
