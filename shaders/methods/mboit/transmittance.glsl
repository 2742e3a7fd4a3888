// Moment-based OIT (Münstermann, Krumpen, Klein, Peters, "Moment-Based Order-Independent
// Transparency", Proc. ACM CGIT 1(1), 2018): reconstruction of the transmittance in front of a
// depth z from b_0 and 2m power moments (m = MFR_MBOIT_M: 2 or 3), after moment shadow mapping
// (Peters & Klein, i3D 2015, Algorithm 2 for m = 2; Peters et al. 2016 for m = 3).
//
// Normalised moments b_k / b_0 describe the distribution of absorbance over warped depth. Among
// all distributions with these moments, the least and greatest absorbance strictly in front of z
// are attained by the unique one supported on z and m further points: the roots of the
// polynomial with coefficients c = H⁻¹·(1, z, …, z^m), H the (m+1)×(m+1) Hankel matrix of the
// moments (b_{i+j}). Its mass in front of z is the lower bound, plus its mass at z the upper bound.
// Because that distribution reproduces every moment up to degree 2m, Σ_i w_i·f(x_i) = Σ_k p_k·b_k
// for the interpolation polynomial p of degree m through (x_i, f(x_i)); so the weights w_i are
// never formed. f is 1 in front of z, 0 behind, and the overestimation β at z itself: the result
// is (1 − β)·lower + β·upper (the paper's blend between the bounds).
//
// The moments are first biased towards those of a fixed distribution (the paper's bias vectors,
// mixed in with weight uMomentBias) so H stays positive definite in float arithmetic.
#ifndef MFR_MBOIT_TRANSMITTANCE_GLSL
#define MFR_MBOIT_TRANSMITTANCE_GLSL

#define MFR_MBOIT_N (MFR_MBOIT_M + 1)
#define MFR_MBOIT_K (2 * MFR_MBOIT_M + 1)

uniform float uMomentBias;
uniform float uOverestimation;

#if MFR_MBOIT_M == 2
const float kBiasMoments[MFR_MBOIT_K] = float[MFR_MBOIT_K](1.0, 0.0, 0.375, 0.0, 0.375);
#else
const float kBiasMoments[MFR_MBOIT_K] = float[MFR_MBOIT_K](1.0, 0.0, 0.48, 0.0, 0.451, 0.0, 0.45);
#endif

// The m real roots of q[0] + q[1]·x + … + q[m]·x^m.
void mfrPolynomialRoots(float q[MFR_MBOIT_N], out float roots[MFR_MBOIT_M]) {
#if MFR_MBOIT_M == 2
  // Stable quadratic formula: no cancellation between −q1 and the square root.
  float disc = sqrt(max(q[1] * q[1] - 4.0 * q[2] * q[0], 0.0));
  float s = -0.5 * (q[1] + (q[1] >= 0.0 ? disc : -disc));
  if (s == 0.0) s = 1e-30;
  roots[0] = s / q[2];
  roots[1] = q[0] / s;
#else
  // Monic cubic x³ + A·x² + B·x + C; with x = t − A/3 it becomes t³ + p·t + r = 0, whose three real
  // roots (guaranteed for a positive definite H) follow from the trigonometric method.
  float A = q[2] / q[3], B = q[1] / q[3], C = q[0] / q[3];
  float p = min(B - A * A / 3.0, -1e-20);  // three real roots need p < 0; rounding may cross 0
  float r = 2.0 * A * A * A / 27.0 - A * B / 3.0 + C;
  float amplitude = 2.0 * sqrt(-p / 3.0);
  float theta = acos(clamp(3.0 * r / (p * amplitude), -1.0, 1.0)) / 3.0;
  const float third = 2.0943951023931957;  // 2π/3
  for (int k = 0; k < 3; ++k) roots[k] = amplitude * cos(theta - third * float(k)) - A / 3.0;
#endif
}

// Transmittance exp(−absorbance in front of z) from b0 and the raw (not normalised) moments
// raw[k−1] = Σ a·z'^k, k = 1..2m.
float mfrTransmittanceAt(float b0, float raw[MFR_MBOIT_K - 1], float z) {
  if (b0 < 1e-6) return 1.0;
  float b[MFR_MBOIT_K];
  b[0] = 1.0;
  for (int k = 1; k < MFR_MBOIT_K; ++k) b[k] = mix(raw[k - 1] / b0, kBiasMoments[k], uMomentBias);

  // H = L·D·Lᵀ (L unit lower triangular), then H·c = (1, z, …, z^m).
  float L[MFR_MBOIT_N][MFR_MBOIT_N];
  float D[MFR_MBOIT_N];
  for (int j = 0; j < MFR_MBOIT_N; ++j) {
    float d = b[2 * j];
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k] * D[k];
    D[j] = d;
    for (int i = j + 1; i < MFR_MBOIT_N; ++i) {
      float l = b[i + j];
      for (int k = 0; k < j; ++k) l -= L[i][k] * L[j][k] * D[k];
      L[i][j] = l / d;
    }
  }
  float c[MFR_MBOIT_N];
  float power = 1.0;
  for (int i = 0; i < MFR_MBOIT_N; ++i) {
    float y = power;
    for (int k = 0; k < i; ++k) y -= L[i][k] * c[k];
    c[i] = y;
    power *= z;
  }
  for (int i = 0; i < MFR_MBOIT_N; ++i) c[i] /= D[i];
  for (int i = MFR_MBOIT_N - 1; i >= 0; --i)
    for (int k = i + 1; k < MFR_MBOIT_N; ++k) c[i] -= L[k][i] * c[k];

  // Support points x_0 = z, x_1..x_m = roots of c; f at each.
  float roots[MFR_MBOIT_M];
  mfrPolynomialRoots(c, roots);
  float x[MFR_MBOIT_N];
  float dd[MFR_MBOIT_N];
  x[0] = z;
  dd[0] = uOverestimation;
  for (int i = 1; i < MFR_MBOIT_N; ++i) {
    x[i] = roots[i - 1];
    dd[i] = x[i] < z ? 1.0 : 0.0;
  }
  // Newton divided differences, then the monomial coefficients of the interpolation polynomial.
  for (int j = 1; j < MFR_MBOIT_N; ++j)
    for (int i = MFR_MBOIT_N - 1; i >= j; --i) dd[i] = (dd[i] - dd[i - 1]) / (x[i] - x[i - j]);
  float poly[MFR_MBOIT_N];
  for (int i = 0; i < MFR_MBOIT_N; ++i) poly[i] = 0.0;
  poly[0] = dd[MFR_MBOIT_N - 1];
  for (int k = MFR_MBOIT_N - 2; k >= 0; --k) {
    for (int i = MFR_MBOIT_N - 1; i >= 1; --i) poly[i] = poly[i - 1] - x[k] * poly[i];
    poly[0] = dd[k] - x[k] * poly[0];
  }
  float inFront = 0.0;
  for (int i = 0; i < MFR_MBOIT_N; ++i) inFront += poly[i] * b[i];
  if (isnan(inFront) || isinf(inFront)) inFront = 0.5;  // degenerate moments: no better guess
  return clamp(exp(-b0 * inFront), 0.0, 1.0);
}
#endif
