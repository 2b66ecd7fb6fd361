/// \file portable_math.hpp
/// Elementary functions that give the same bits on every CPU, for computations whose results
/// are committed byte for byte (the open body models, docs/models.md).
///
/// Why hand-written: glibc's libm picks its sin, cos, exp, log and pow at run time from the CPU
/// (FMA and non-FMA builds of the same code), and the variants differ in the last bit; a model
/// generated on a CPU without FMA would differ from one generated with it. These functions use
/// only +, -, *, /, sqrt, rint, frexp and ldexp, which IEEE 754 defines exactly, in a fixed
/// order (the project compiles with -ffp-contract=off), so their results depend on nothing but
/// the input. Accuracy: within 2 ulp of the true value on the documented ranges (tested against
/// libm in tests/caliper/test_portable_math.cpp). Not faster than libm; use them only where
/// reproducibility across machines matters.
#pragma once

namespace caliper::portable {

/// sin(x), radians. Accurate for |x| < 1e5 (Cody-Waite reduction); larger |x| lose accuracy
/// (still deterministic).
double sin(double x);
/// cos(x), radians; as sin().
double cos(double x);
/// Natural logarithm; x <= 0 gives NaN (x == 0: -inf), +inf gives +inf.
double log(double x);
/// e^x; overflow gives +inf, underflow 0.
double exp(double x);
/// x^y for x > 0 as exp(y log x) (relative error grows with |y log x|: ~1e-15 for |y log x| < 10);
/// x == 0 gives 0 for y > 0; x < 0 gives NaN.
double pow(double x, double y);
/// sqrt(a^2 + b^2) (no overflow protection: for lengths in metres).
double hypot(double a, double b);
/// Real cube root (negative x gives a negative root).
double cbrt(double x);

}  // namespace caliper::portable
