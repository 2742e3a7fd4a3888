// LDR-FLIP, implemented from the paper:
//   P. Andersson, J. Nilsson, T. Akenine-Möller, M. Oskarsson, K. Åström and M. D. Fairchild,
//   "FLIP: A Difference Evaluator for Alternating Images",
//   Proc. ACM on Computer Graphics and Interactive Techniques 3(2), 2020.
// All constants are the published ones. Where the paper leaves room, we follow NVIDIA's BSD-3
// reference implementation so that our numbers agree with its tool: every 2D filter is applied
// as two 1D passes (exact here: each kernel is a Gaussian, a sum of Gaussians, or a Gaussian
// times a polynomial in one axis), images are clamped at their borders, and the arithmetic is
// single precision in the same order of operations.
#include "flip_internal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"
#include "mfr/reference/metrics.hpp"

namespace mfr {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// ---------------------------------------------------------------------------------------------
// Colour spaces. sRGB primaries, D65 white; XYZ is scaled so that white has Y = 1.

struct Vec3 {
  float x = 0, y = 0, z = 0;
};

// Linear RGB -> XYZ, the sRGB matrix in its exact rational form.
constexpr float kRgbToXyz[3][3] = {{10135552.0f / 24577794.0f, 8788810.0f / 24577794.0f, 4435075.0f / 24577794.0f},
                                   {2613072.0f / 12288897.0f, 8788810.0f / 12288897.0f, 887015.0f / 12288897.0f},
                                   {1425312.0f / 73733382.0f, 8788810.0f / 73733382.0f, 70074185.0f / 73733382.0f}};
// Its inverse (XYZ -> linear RGB), to the precision published with the sRGB standard.
constexpr float kXyzToRgb[3][3] = {{3.241003275f, -1.537398934f, -0.498615861f},
                                   {-0.969224334f, 1.875930071f, 0.041554224f},
                                   {0.055639423f, -0.204011202f, 1.057148933f}};
// Reference white for YCxCz and L*a*b*: the XYZ of linear RGB (1,1,1), i.e. the row sums above.
constexpr Vec3 kWhite = {0.950428545f, 1.0f, 1.088900371f};
constexpr Vec3 kInvWhite = {1.052156925f, 1.0f, 0.918357670f};

Vec3 mul(const float (&m)[3][3], Vec3 v) {
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// YCxCz, the paper's opponent space: L*a*b* without its cube root, so it is linear in XYZ and
// spatial filtering in it is meaningful.
Vec3 xyzToYcxcz(Vec3 xyz) {
  const float x = xyz.x * kInvWhite.x, y = xyz.y * kInvWhite.y, z = xyz.z * kInvWhite.z;
  return {116.0f * y - 16.0f, 500.0f * (x - y), 200.0f * (y - z)};
}

Vec3 ycxczToXyz(Vec3 c) {
  const float y = (c.x + 16.0f) / 116.0f;
  const float cx = c.y / 500.0f;
  const float cz = c.z / 200.0f;
  return {(y + cx) * kWhite.x, y * kWhite.y, (y - cz) * kWhite.z};
}

float labF(float t) {
  constexpr float delta = 6.0f / 29.0f;
  constexpr float deltaCube = delta * delta * delta;
  // pow(t, 1/3) rather than cbrt: it rounds like the reference implementation, which keeps
  // errors that sit on a colour-map step on the same side as its tool's output.
  return t > deltaCube ? std::pow(t, 1.0f / 3.0f) : t / (3.0f * delta * delta) + 4.0f / 29.0f;
}

Vec3 xyzToLab(Vec3 xyz) {
  const float fx = labF(xyz.x * kInvWhite.x);
  const float fy = labF(xyz.y * kInvWhite.y);
  const float fz = labF(xyz.z * kInvWhite.z);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

// Hunt adjustment: chroma shrinks with lightness, as perceived colourfulness does.
Vec3 hunt(Vec3 lab) {
  return {lab.x, 0.01f * lab.x * lab.y, 0.01f * lab.x * lab.z};
}

// Linear RGB in [0,1] -> Hunt-adjusted L*a*b*, the space where colour distances are taken.
Vec3 linearRgbToHuntLab(Vec3 rgb) {
  return hunt(xyzToLab(mul(kRgbToXyz, rgb)));
}

// HyAB distance: city-block in lightness plus Euclidean in chroma; behaves better than
// ΔE*ab for large differences.
float hyab(Vec3 a, Vec3 b) {
  const float da = a.y - b.y, db = a.z - b.z;
  return std::fabs(a.x - b.x) + std::sqrt(da * da + db * db);
}

// ---------------------------------------------------------------------------------------------
// Published constants.

constexpr float kQc = 0.7f;   // exponent on the colour difference
constexpr float kPc = 0.4f;   // fraction of cmax where the error remapping changes slope
constexpr float kPt = 0.95f;  // error assigned at pc·cmax
constexpr float kW = 0.082f;  // edge detector width (peak to trough, degrees of visual angle)
constexpr float kQf = 0.5f;   // exponent on the feature difference

// CSF of each opponent channel as a sum of two Gaussians in the spatial domain:
//   s(r) = a1·sqrt(π/b1)·exp(−π²r²/b1) + a2·sqrt(π/b2)·exp(−π²r²/b2), r in degrees.
struct CsfConstants {
  float a1, b1, a2, b2;
};
constexpr CsfConstants kCsfA = {1.0f, 0.0047f, 0.0f, 1.0e-5f};
constexpr CsfConstants kCsfRG = {1.0f, 0.0053f, 0.0f, 1.0e-5f};
constexpr CsfConstants kCsfBY = {34.1f, 0.04f, 13.5f, 0.025f};

// ---------------------------------------------------------------------------------------------
// Float planes and separable filtering with clamp-to-edge borders.

struct Plane {
  int width = 0;
  int height = 0;
  std::unique_ptr<float[]> v;  // not zero-filled: every pass writes all of its output

  Plane() = default;
  Plane(int w, int h)
      : width(w),
        height(h),
        v(std::make_unique_for_overwrite<float[]>(static_cast<std::size_t>(w) * static_cast<std::size_t>(h))) {}
  [[nodiscard]] std::size_t size() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  [[nodiscard]] float* row(int y) { return v.get() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width); }
  [[nodiscard]] const float* row(int y) const {
    return v.get() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
  }
};

using Kernel = std::vector<float>;  // 2r+1 taps, centre in the middle

// Pixels per block in the filter loops: a fixed-size block of local accumulators is what lets the
// compiler vectorise them at -O2; each pixel still sums its taps in order from the first.
constexpr int kBlock = 8;

// out[x] = Σk kernel[k]·taps(k)[x] for x in [0, w), where taps(k) points at the input aligned with
// tap k (a shifted padded row for horizontal passes, a clamped row for vertical ones).
template <typename Taps>
void convolve(int w, const Kernel& kernel, Taps taps, float* out) {
  int x = 0;
  for (; x + kBlock <= w; x += kBlock) {
    float acc[kBlock] = {};
    for (std::size_t k = 0; k < kernel.size(); ++k) {
      const float wk = kernel[k];
      const float* in = taps(k) + x;
      for (int j = 0; j < kBlock; ++j) acc[j] += wk * in[j];
    }
    for (int j = 0; j < kBlock; ++j) out[x + j] = acc[j];
  }
  for (; x < w; ++x) {
    float acc = 0.0f;
    for (std::size_t k = 0; k < kernel.size(); ++k) acc += kernel[k] * taps(k)[x];
    out[x] = acc;
  }
}

// Horizontal pass of every kernel in kernels over src: one output plane per kernel.
template <std::size_t N>
std::array<Plane, N> filterRows(const Plane& src, const std::array<const Kernel*, N>& kernels) {
  const int w = src.width;
  const int r = static_cast<int>(kernels[0]->size() / 2);  // all kernels of one pass have one size
  std::array<Plane, N> out;
  for (Plane& p : out) p = Plane(w, src.height);
  std::vector<float> padded(static_cast<std::size_t>(w + 2 * r));
  for (int y = 0; y < src.height; ++y) {
    const float* in = src.row(y);
    for (int i = 0; i < w + 2 * r; ++i) padded[static_cast<std::size_t>(i)] = in[std::clamp(i - r, 0, w - 1)];
    for (std::size_t n = 0; n < N; ++n) {
      convolve(
          w, *kernels[n], [&](std::size_t k) { return padded.data() + k; }, out[n].row(y));
    }
  }
  return out;
}

// Vertical pass of kernel over src for output row y only, so that the per-pixel work that follows
// can run row by row without storing whole filtered planes.
void filterColumnAt(const Plane& src, const Kernel& kernel, int y, float* out) {
  const int r = static_cast<int>(kernel.size() / 2);
  const auto taps = [&](std::size_t k) { return src.row(std::clamp(y + static_cast<int>(k) - r, 0, src.height - 1)); };
  convolve(src.width, kernel, taps, out);
}

// 8-bit sRGB -> Y, Cx, Cz planes.
std::array<Plane, 3> toYcxcz(const ImageRGBA8& image) {
  std::array<float, 256> linear{};
  for (int i = 0; i < 256; ++i) linear[static_cast<std::size_t>(i)] = srgbToLinear(static_cast<float>(i) / 255.0f);
  std::array<Plane, 3> out{Plane(image.width, image.height), Plane(image.width, image.height),
                           Plane(image.width, image.height)};
  for (std::size_t i = 0; i < out[0].size(); ++i) {
    const std::uint8_t* p = &image.pixels[i * 4];
    const Vec3 c = xyzToYcxcz(mul(kRgbToXyz, {linear[p[0]], linear[p[1]], linear[p[2]]}));
    out[0].v[i] = c.x;
    out[1].v[i] = c.y;
    out[2].v[i] = c.z;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Colour pipeline.

int csfRadius(float ppd) {
  // Cover three standard deviations of the widest Gaussian: exp(−π²r²/b) has σ = sqrt(b/(2π²)).
  const float bMax = std::max({kCsfA.b1, kCsfA.b2, kCsfRG.b1, kCsfRG.b2, kCsfBY.b1, kCsfBY.b2});
  return static_cast<int>(std::ceil(3.0f * std::sqrt(bMax / (2.0f * kPi * kPi)) * ppd));
}

float gaussianTerm(float x2, float a, float b) {
  return a * std::sqrt(kPi / b) * std::exp(-kPi * kPi * x2 / b);
}

struct CsfKernels {
  Kernel achromatic, redGreen, blueYellow1, blueYellow2;
};

// 1D kernels whose outer products give the normalised 2D CSF filters. A and RG are single
// Gaussians (a2 = 0): normalise each 1D kernel to sum 1. BY is a sum of two Gaussians, which is
// not separable as a whole, so each term is split into sqrt(a·sqrt(π/b))·exp(−π²x²/b) per axis,
// filtered separately and summed; scaling both 1D kernels by 1/sqrt(S1² + S2²) makes the implied
// 2D kernel sum to 1, exactly as normalising the 2D sum-of-Gaussians would.
CsfKernels csfKernels(float ppd) {
  const int r = csfRadius(ppd);
  const float dx = 1.0f / ppd;  // degrees per pixel
  CsfKernels k;
  float sumA = 0, sumRG = 0, sumBY1 = 0, sumBY2 = 0;
  for (int i = -r; i <= r; ++i) {
    const float x = static_cast<float>(i) * dx;
    const float x2 = x * x;
    k.achromatic.push_back(gaussianTerm(x2, kCsfA.a1, kCsfA.b1));
    k.redGreen.push_back(gaussianTerm(x2, kCsfRG.a1, kCsfRG.b1));
    k.blueYellow1.push_back(std::sqrt(kCsfBY.a1 * std::sqrt(kPi / kCsfBY.b1)) * std::exp(-kPi * kPi * x2 / kCsfBY.b1));
    k.blueYellow2.push_back(std::sqrt(kCsfBY.a2 * std::sqrt(kPi / kCsfBY.b2)) * std::exp(-kPi * kPi * x2 / kCsfBY.b2));
    sumA += k.achromatic.back();
    sumRG += k.redGreen.back();
    sumBY1 += k.blueYellow1.back();
    sumBY2 += k.blueYellow2.back();
  }
  const float normBY = 1.0f / std::sqrt(sumBY1 * sumBY1 + sumBY2 * sumBY2);
  const float normA = 1.0f / sumA, normRG = 1.0f / sumRG;
  for (float& v : k.achromatic) v *= normA;
  for (float& v : k.redGreen) v *= normRG;
  for (float& v : k.blueYellow1) v *= normBY;
  for (float& v : k.blueYellow2) v *= normBY;
  return k;
}

// The horizontal half of the CSF filtering of one image: Y, Cx, and Cz with both BY terms.
class CsfFiltered {
 public:
  CsfFiltered(const std::array<Plane, 3>& ycxcz, const CsfKernels& k)
      : kernels_(k), buffer_(static_cast<std::size_t>(ycxcz[0].width) * 4) {
    y_ = std::move(filterRows<1>(ycxcz[0], {&k.achromatic})[0]);
    cx_ = std::move(filterRows<1>(ycxcz[1], {&k.redGreen})[0]);
    auto cz = filterRows<2>(ycxcz[2], {&k.blueYellow1, &k.blueYellow2});
    cz1_ = std::move(cz[0]);
    cz2_ = std::move(cz[1]);
  }

  // Finishes the filtering for row y and converts it to Hunt-adjusted L*a*b*, after clamping to
  // the RGB cube (filtering can leave it).
  void perceivedRow(int y, std::vector<Vec3>& out) {
    const std::size_t w = static_cast<std::size_t>(y_.width);
    float* fy = buffer_.data();
    float* fcx = fy + w;
    float* fcz1 = fcx + w;
    float* fcz2 = fcz1 + w;
    filterColumnAt(y_, kernels_.achromatic, y, fy);
    filterColumnAt(cx_, kernels_.redGreen, y, fcx);
    filterColumnAt(cz1_, kernels_.blueYellow1, y, fcz1);
    filterColumnAt(cz2_, kernels_.blueYellow2, y, fcz2);
    out.resize(w);
    for (std::size_t x = 0; x < w; ++x) {
      Vec3 rgb = mul(kXyzToRgb, ycxczToXyz({fy[x], fcx[x], fcz1[x] + fcz2[x]}));
      rgb = {std::clamp(rgb.x, 0.0f, 1.0f), std::clamp(rgb.y, 0.0f, 1.0f), std::clamp(rgb.z, 0.0f, 1.0f)};
      out[x] = linearRgbToHuntLab(rgb);
    }
  }

 private:
  const CsfKernels& kernels_;
  std::vector<float> buffer_;
  Plane y_, cx_, cz1_, cz2_;  // filtered along x with the A, RG, BY1, BY2 kernels
};

// ΔEc in [0,1]: HyAB^qc remapped so that the largest difference of the gamut (pure green vs
// pure blue, cmax) maps to 1, with a steeper slope below pc·cmax, where errors are assigned up to pt.
Plane colourDifference(const std::array<Plane, 3>& ref, const std::array<Plane, 3>& test, float ppd) {
  const CsfKernels k = csfKernels(ppd);
  CsfFiltered a(ref, k);
  CsfFiltered b(test, k);
  const float cmax = std::pow(hyab(linearRgbToHuntLab({0, 1, 0}), linearRgbToHuntLab({0, 0, 1})), kQc);
  const float pccmax = kPc * cmax;
  Plane out(ref[0].width, ref[0].height);
  std::vector<Vec3> rowA, rowB;
  for (int y = 0; y < out.height; ++y) {
    a.perceivedRow(y, rowA);
    b.perceivedRow(y, rowB);
    float* o = out.row(y);
    for (int x = 0; x < out.width; ++x) {
      const float d = std::pow(hyab(rowA[static_cast<std::size_t>(x)], rowB[static_cast<std::size_t>(x)]), kQc);
      o[x] = d < pccmax ? d * (kPt / pccmax) : kPt + ((d - pccmax) / (cmax - pccmax)) * (1.0f - kPt);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Feature pipeline: edges (first derivative of a Gaussian) and points (second derivative)
// on the achromatic channel.

struct FeatureKernels {
  Kernel g, dg, ddg;  // Gaussian, its 1st and 2nd derivative along one axis
};

// σ = w/2 · ppd pixels (w is peak to trough, i.e. two standard deviations), radius ⌈3σ⌉.
// The 2D detectors are d(x)·g(y); the paper normalises their positive weights to sum 1 and the
// negative ones to −1. The sign depends only on x, so that is the same as normalising d's
// positive and negative parts that way and g to sum 1, which keeps them separable.
FeatureKernels featureKernels(float ppd) {
  const float sigma = 0.5f * kW * ppd;
  const int r = static_cast<int>(std::ceil(3.0f * sigma));
  FeatureKernels k;
  float gSum = 0, dgPos = 0, dgNeg = 0, ddgPos = 0, ddgNeg = 0;
  for (int i = -r; i <= r; ++i) {
    const float x = static_cast<float>(i);
    const float g = std::exp(-(x * x) / (2.0f * sigma * sigma));
    const float dg = -x * g;
    const float ddg = (x * x / (sigma * sigma) - 1.0f) * g;
    k.g.push_back(g);
    k.dg.push_back(dg);
    k.ddg.push_back(ddg);
    gSum += g;
    (dg > 0 ? dgPos : dgNeg) += std::fabs(dg);
    (ddg > 0 ? ddgPos : ddgNeg) += std::fabs(ddg);
  }
  // At a few pixels per degree or less σ is a small fraction of a pixel and the off-centre weights
  // underflow to 0: a part with no weight stays 0 (the detector sees nothing at that scale)
  // instead of 0 / 0 = NaN.
  const auto share = [](float v, float positive, float negative) {
    const float part = v > 0 ? positive : negative;
    return part > 0 ? v / part : 0.0f;
  };
  for (std::size_t i = 0; i < k.g.size(); ++i) {
    k.g[i] /= gSum;
    k.dg[i] = share(k.dg[i], dgPos, dgNeg);
    k.ddg[i] = share(k.ddg[i], ddgPos, ddgNeg);
  }
  return k;
}

// The horizontal half of the feature filtering of one image's achromatic channel.
class FeatureFiltered {
 public:
  FeatureFiltered(const Plane& ycxczY, const FeatureKernels& k)
      : kernels_(k),
        rows_(filterRows<3>(normalised(ycxczY), {&k.g, &k.dg, &k.ddg})),
        buffer_(static_cast<std::size_t>(ycxczY.width) * 4) {}

  // Edge and point detector magnitudes for row y.
  void featureRow(int y, std::vector<float>& edge, std::vector<float>& point) {
    const std::size_t w = static_cast<std::size_t>(rows_[0].width);
    float* dx = buffer_.data();
    float* ddx = dx + w;
    float* dy = ddx + w;
    float* ddy = dy + w;
    filterColumnAt(rows_[1], kernels_.g, y, dx);     // d/dx of the Gaussian in x, Gaussian in y
    filterColumnAt(rows_[2], kernels_.g, y, ddx);    // d²/dx², Gaussian in y
    filterColumnAt(rows_[0], kernels_.dg, y, dy);    // Gaussian in x, d/dy
    filterColumnAt(rows_[0], kernels_.ddg, y, ddy);  // Gaussian in x, d²/dy²
    edge.resize(w);
    point.resize(w);
    for (std::size_t x = 0; x < w; ++x) {
      edge[x] = std::sqrt(dx[x] * dx[x] + dy[x] * dy[x]);
      point[x] = std::sqrt(ddx[x] * ddx[x] + ddy[x] * ddy[x]);
    }
  }

 private:
  // YCxCz's Y is 116·f(Y) − 16; bring it back to [0,1].
  static Plane normalised(const Plane& y) {
    Plane out(y.width, y.height);
    for (std::size_t i = 0; i < y.size(); ++i) out.v[i] = y.v[i] * (1.0f / 116.0f) + 16.0f / 116.0f;
    return out;
  }

  const FeatureKernels& kernels_;
  std::array<Plane, 3> rows_;  // filtered along x with g, dg, ddg
  std::vector<float> buffer_;
};

// ΔEf in [0,1]: the larger of the edge and point differences, scaled by 1/√2 (the largest
// possible magnitude) and raised to qf.
Plane featureDifference(const Plane& refY, const Plane& testY, float ppd) {
  const FeatureKernels k = featureKernels(ppd);
  FeatureFiltered a(refY, k);
  FeatureFiltered b(testY, k);
  Plane out(refY.width, refY.height);
  const float scale = 1.0f / std::sqrt(2.0f);
  std::vector<float> edgeA, pointA, edgeB, pointB;
  for (int y = 0; y < out.height; ++y) {
    a.featureRow(y, edgeA, pointA);
    b.featureRow(y, edgeB, pointB);
    float* o = out.row(y);
    for (std::size_t x = 0; x < edgeA.size(); ++x) {
      const float edge = std::fabs(edgeA[x] - edgeB[x]);
      const float point = std::fabs(pointA[x] - pointB[x]);
      o[x] = std::pow(scale * std::max(edge, point), kQf);
    }
  }
  return out;
}

void checkImage(const ImageRGBA8& image, const char* role) {
  if (image.width < 0 || image.height < 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4) {
    throw Error("flip", std::string(role) + " image has " + std::to_string(image.pixels.size()) + " bytes for " +
                            std::to_string(image.width) + "x" + std::to_string(image.height) + " pixels");
  }
}

}  // namespace

double weightedPercentileSorted(const std::vector<float>& sorted, double total, double p) {
  if (sorted.empty()) return 0.0;
  const double threshold = p * total;
  double running = 0.0;
  for (const float v : sorted) {
    running += v;
    if (running > threshold) return v;
  }
  return sorted.back();  // p ≥ 1 (or rounding): the largest value
}

FlipResult flip(const ImageRGBA8& reference, const ImageRGBA8& test, double pixelsPerDegree) {
  checkImage(reference, "reference");
  checkImage(test, "test");
  if (reference.width != test.width || reference.height != test.height) {
    throw Error("flip", "image sizes differ: reference " + std::to_string(reference.width) + "x" +
                            std::to_string(reference.height) + ", test " + std::to_string(test.width) + "x" +
                            std::to_string(test.height));
  }
  // Below 0.01 the filters are degenerate (at 1e-30 every value came out NaN).
  if (!(pixelsPerDegree >= 0.01) || !(pixelsPerDegree <= 1e4)) {
    throw Error("flip", "pixels per degree must be in [0.01, 10000], got " + std::to_string(pixelsPerDegree));
  }
  // Float planes at the peak, in the colour pass: the error map, each image's three YCxCz planes
  // and four planes filtered along x, and the pass's output.
  requireHostMemory(
      "flip", "FLIP of " + std::to_string(reference.width) + "x" + std::to_string(reference.height) + " pixels",
      static_cast<std::uint64_t>(reference.width) * static_cast<std::uint64_t>(reference.height) * 16 * sizeof(float));
  FlipResult result;
  result.errorMap = ImageF(reference.width, reference.height, 1);
  if (reference.empty()) return result;

  const float ppd = static_cast<float>(pixelsPerDegree);
  const std::array<Plane, 3> ref = toYcxcz(reference);
  const std::array<Plane, 3> tst = toYcxcz(test);
  const Plane colour = colourDifference(ref, tst, ppd);
  const Plane feature = featureDifference(ref[0], tst[0], ppd);

  // Final error: features raise the colour error towards 1 where edges or points differ.
  std::vector<float>& e = result.errorMap.data;
  double sum = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    e[i] = std::pow(colour.v[i], 1.0f - feature.v[i]);
    sum += e[i];
  }

  std::vector<float> sorted = e;
  std::sort(sorted.begin(), sorted.end());
  FlipStats& s = result.stats;
  s.mean = sum / static_cast<double>(e.size());
  s.min = sorted.front();
  s.max = sorted.back();
  s.p25 = weightedPercentileSorted(sorted, sum, 0.25);
  s.p50 = weightedPercentileSorted(sorted, sum, 0.50);
  s.p75 = weightedPercentileSorted(sorted, sum, 0.75);
  return result;
}

}  // namespace mfr
