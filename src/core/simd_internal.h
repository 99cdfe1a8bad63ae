/* simd_internal.h -- the one place the core asks for SIMD intrinsics: ARMv7E-M's SIMD32 (uqsub8, usad8, sel ...; SONAR_SIMD32) and x86-64's SSE2 (psadbw, pminub ...; SONAR_SSE2), each 1 where it exists with its header included, else 0; no code, no RAM. */
#ifndef SONAR_SIMD_INTERNAL_H
#define SONAR_SIMD_INTERNAL_H

#if defined(__ARM_FEATURE_SIMD32) && __ARM_FEATURE_SIMD32
#include <arm_acle.h>
#define SONAR_SIMD32 1
#else
#define SONAR_SIMD32 0
#endif

/*
 * SSE2 is in every x86-64 CPU. Only the few passes whose sums -O2 cannot vectorise from plain C (eight bytes
 * summed into one 16-bit count) use it; every one keeps its plain C loop, the one arm64 runs (make test-arm),
 * and gives the same numbers (the tests compare them with a plain scan). -DSONAR_NO_SSE2 builds without it.
 */
#if defined(__SSE2__) && !defined(SONAR_NO_SSE2) && !SONAR_SIMD32
#include <emmintrin.h>
#define SONAR_SSE2 1
#else
#define SONAR_SSE2 0
#endif

#endif
