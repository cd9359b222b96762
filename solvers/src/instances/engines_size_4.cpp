#define NLOBS_INSTANCE_SIZE 4
#include "engines_at_size.inc"
