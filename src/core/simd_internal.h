/* simd_internal.h -- the one place the core asks for ARMv7E-M's SIMD32 intrinsics (uqsub8, usad8, sel ...): SONAR_SIMD32 is 1 where they exist, with arm_acle.h included, else 0; no code, no RAM. */
#ifndef SONAR_SIMD_INTERNAL_H
#define SONAR_SIMD_INTERNAL_H

#if defined(__ARM_FEATURE_SIMD32) && __ARM_FEATURE_SIMD32
#include <arm_acle.h>
#define SONAR_SIMD32 1
#else
#define SONAR_SIMD32 0
#endif

#endif
