// Small host/device helpers shared by the CPU and CUDA formulas (ODEMAG_HD:
// include/odemag/vec3.h).
#pragma once

#include "odemag/vec3.h"

// fmax(a, b), inlined (on the host the library's fmax is a call, about 1% of
// the crane's time): the larger of the two, the other one where one is NaN.
ODEMAG_HD double larger(double a, double b) { return (b > a || a != a) ? b : a; }
