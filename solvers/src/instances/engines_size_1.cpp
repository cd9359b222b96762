#define NLOBS_INSTANCE_SIZE 1
#include "engines_at_size.inc"
