// The SMPL forward pass: Loper, Mahmood, Romero, Pons-Moll, Black, "SMPL: A Skinned Multi-Person
// Linear Model", SIGGRAPH Asia 2015, eqs. (1)-(4) and section 3: shape blend shapes, joint
// regression, pose blend shapes, Rodrigues, kinematic chain, linear blend skinning.
#include "smpl/evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "smpl/simd.hpp"

namespace smpl {
namespace {

// Below this angle (radians) Rodrigues' coefficients come from their Taylor series. At 1e-3 the
// first omitted terms (t^6/5040, t^6/40320) are below 1e-21, far under double rounding.
constexpr double kSmallAngle = 1e-3;

// Kernel variants (simd.hpp): each hot loop below is written once as an always-inline body and
// compiled into one function per x86-64 level (baseline SSE2, AVX2, AVX-512F); a dispatcher picks
// the variant of smpl::simd_level() at each call. Explicit variants instead of GCC's target_clones
// so that tests and benchmarks can run each one and CALIPER_SIMD can pin one. The bodies vectorise
// across independent outputs only and the project builds with -ffp-contract=off, so every variant
// computes bit-identical results (tests/smpl/test_simd.cpp).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// Each body is a template on the vector width in bytes, so every variant uses vectors as wide as
// its registers (16 bytes for SSE2, 32 for AVX2, 64 for AVX-512F): a 64-byte vector on an AVX2
// target is split into register pairs and spills, a 32-byte one on SSE2 likewise.
#define SMPL_KERNEL_BODY   \
  template <int kVecBytes> \
  inline __attribute__((always_inline))
// NOLINTBEGIN(bugprone-macro-parentheses): args is a parenthesised argument list, name##_body<16>
// args. `head` goes before each function: empty, or `template <typename Scalar>` for a kernel
// written once for float and double (the body template deduces Scalar from the arguments).
#define SMPL_KERNEL_VARIANTS_WITH(head, name, params, args)           \
  head void name##_baseline params {                                  \
    name##_body<16> args;                                             \
  }                                                                   \
  head __attribute__((target("avx2"))) void name##_avx2 params {      \
    name##_body<32> args;                                             \
  }                                                                   \
  head __attribute__((target("avx512f"))) void name##_avx512 params { \
    name##_body<64> args;                                             \
  }                                                                   \
  head void name params {                                             \
    switch (simd_level()) {                                           \
      case SimdLevel::kAvx512:                                        \
        name##_avx512 args;                                           \
        return;                                                       \
      case SimdLevel::kAvx2:                                          \
        name##_avx2 args;                                             \
        return;                                                       \
      case SimdLevel::kBaseline:                                      \
        break;                                                        \
    }                                                                 \
    name##_baseline args;                                             \
  }
// NOLINTEND(bugprone-macro-parentheses)
#else
// Other architectures (AArch64 NEON, ...): one variant with 16-byte vectors.
#define SMPL_KERNEL_BODY   \
  template <int kVecBytes> \
  inline
#define SMPL_KERNEL_VARIANTS_WITH(head, name, params, args) \
  head void name params {                                   \
    name##_body<16> args;                                   \
  }
#endif
#define SMPL_KERNEL_VARIANTS(name, params, args) SMPL_KERNEL_VARIANTS_WITH(, name, params, args)

constexpr size_t kFloatBytes = sizeof(float);

// A GCC/Clang vector of kBytes / sizeof(T) lanes of T.
template <typename T, int kBytes>
struct Vec {
  typedef T type __attribute__((vector_size(kBytes)));
};

// out = t + S[:, :nb] * beta with S column-major (leading dimension ld): the shape blend shapes.
// 8 vectors of rows (16 rows with SSE2, 32 with AVX2, 64 with AVX-512) are accumulated in
// registers while every column's segment streams past: shapedirs is read exactly once. Each
// output is t + beta_0 S_0 + beta_1 S_1 + ... in this order in every variant and in the tail.
SMPL_KERNEL_BODY
void blend_body(const double* t, const double* S, Eigen::Index ld, Eigen::Index rows,
                const double* beta, Eigen::Index nb, double* out) {
  typedef typename Vec<double, kVecBytes>::type V;
  constexpr Eigen::Index kLanes = kVecBytes / 8;
  constexpr int kAcc = 8;
  constexpr Eigen::Index kRows = kAcc * kLanes;
  Eigen::Index r0 = 0;
  for (; r0 + kRows <= rows; r0 += kRows) {
    V a[kAcc];
#pragma GCC unroll 8
    for (int k = 0; k < kAcc; ++k) std::memcpy(&a[k], t + r0 + k * kLanes, sizeof(V));
    for (Eigen::Index b = 0; b < nb; ++b) {
      const double c = beta[b];
      const double* col = S + b * ld + r0;
#pragma GCC unroll 8
      for (int k = 0; k < kAcc; ++k) {
        V x;
        std::memcpy(&x, col + k * kLanes, sizeof x);
        a[k] += c * x;
      }
    }
#pragma GCC unroll 8
    for (int k = 0; k < kAcc; ++k) std::memcpy(out + r0 + k * kLanes, &a[k], sizeof(V));
  }
  for (; r0 < rows; ++r0) {
    double a = t[r0];
    for (Eigen::Index b = 0; b < nb; ++b) a += beta[b] * S[b * ld + r0];
    out[r0] = a;
  }
}
SMPL_KERNEL_VARIANTS(blend,
                     (const double* t, const double* S, Eigen::Index ld, Eigen::Index rows,
                      const double* beta, Eigen::Index nb, double* out),
                     (t, S, ld, rows, beta, nb, out))

// ---- Batch shape blend shapes (shape_batch): one loaded vector of shapedirs serves G bodies.

// One step of K vectors T of rows r.. for G bodies (body g's betas at beta + g * bstride, its
// output at out + g * ostride): acc_g = t, then acc_g += beta_g[b] * S_b for b = 0, 1, ... in
// this order, as blend_body computes each output. Scalar is double (shape_batch into BodyBatch)
// or float (into BodyBatchF, betas rounded to float by the caller); T is a vector of Scalar, or
// Scalar itself for the tail rows.
template <typename Scalar, typename T, int G, int K>
inline __attribute__((always_inline)) void blend_step(const Scalar* t, const Scalar* S,
                                                      Eigen::Index ld, Eigen::Index r,
                                                      const Scalar* beta, Eigen::Index bstride,
                                                      Eigen::Index nb, Scalar* out,
                                                      Eigen::Index ostride) {
  constexpr Eigen::Index kLanes = static_cast<Eigen::Index>(
      sizeof(T) / sizeof(Scalar));  // NOLINT(bugprone-sizeof-expression): T = Scalar is one lane
  T a[G][K];
#pragma GCC unroll 8
  for (int k = 0; k < K; ++k) {
    T tk;
    std::memcpy(&tk, t + r + k * kLanes, sizeof(T));
#pragma GCC unroll 4
    for (int g = 0; g < G; ++g) a[g][k] = tk;
  }
  for (Eigen::Index b = 0; b < nb; ++b) {
    T x[K];
#pragma GCC unroll 8
    for (int k = 0; k < K; ++k) std::memcpy(&x[k], S + b * ld + r + k * kLanes, sizeof(T));
#pragma GCC unroll 4
    for (int g = 0; g < G; ++g) {
      const Scalar c = beta[g * bstride + b];
#pragma GCC unroll 8
      for (int k = 0; k < K; ++k) a[g][k] += c * x[k];
    }
  }
#pragma GCC unroll 4
  for (int g = 0; g < G; ++g) {
#pragma GCC unroll 8
    for (int k = 0; k < K; ++k)
      std::memcpy(out + g * ostride + r + k * kLanes, &a[g][k], sizeof(T));
  }
}

// Rows [0, rows) of G bodies: steps of K vectors V, then of one vector, then the tail rows one at a
// time.
template <typename Scalar, typename V, int G, int K>
inline __attribute__((always_inline)) void blend_group(const Scalar* t, const Scalar* S,
                                                       Eigen::Index ld, Eigen::Index rows,
                                                       const Scalar* beta, Eigen::Index bstride,
                                                       Eigen::Index nb, Scalar* out,
                                                       Eigen::Index ostride) {
  constexpr Eigen::Index kLanes = static_cast<Eigen::Index>(sizeof(V) / sizeof(Scalar));
  constexpr Eigen::Index kRows = K * kLanes;
  Eigen::Index r = 0;
  for (; r + kRows <= rows; r += kRows)
    blend_step<Scalar, V, G, K>(t, S, ld, r, beta, bstride, nb, out, ostride);
  for (; r + kLanes <= rows; r += kLanes)
    blend_step<Scalar, V, G, 1>(t, S, ld, r, beta, bstride, nb, out, ostride);
  for (; r < rows; ++r)
    blend_step<Scalar, Scalar, G, 1>(t, S, ld, r, beta, bstride, nb, out, ostride);
}

// blend() for `nbodies` bodies over the same rows: body n's betas at beta + n * bstride, its
// output at out + n * ostride. Groups of 4 bodies share every loaded vector of S (2 vectors of
// rows per step, 4 with AVX-512's 32 registers: 8 or 16 accumulators), so a block of S small
// enough for the L1 cache is read from it once per 4 bodies; with Scalar = double each output
// has the bits of blend() (same operations, same order).
template <int kVecBytes, typename Scalar>
inline __attribute__((always_inline)) void blend_batch_body(const Scalar* t, const Scalar* S,
                                                            Eigen::Index ld, Eigen::Index rows,
                                                            const Scalar* beta,
                                                            Eigen::Index bstride, Eigen::Index nb,
                                                            Eigen::Index nbodies, Scalar* out,
                                                            Eigen::Index ostride) {
  typedef typename Vec<Scalar, kVecBytes>::type V;
  constexpr int K = kVecBytes >= 64 ? 4 : 2;
  Eigen::Index n = 0;
  for (; n + 4 <= nbodies; n += 4)
    blend_group<Scalar, V, 4, K>(t, S, ld, rows, beta + n * bstride, bstride, nb, out + n * ostride,
                                 ostride);
  const Scalar* bn = beta + n * bstride;
  Scalar* on = out + n * ostride;
  // The last 1-3 bodies: more vectors of rows per step, so that enough independent sums are in
  // flight to hide the latency of the additions (8 for one body, as blend() has).
  switch (nbodies - n) {
    case 3:
      blend_group<Scalar, V, 3, K + 1>(t, S, ld, rows, bn, bstride, nb, on, ostride);
      break;
    case 2:
      blend_group<Scalar, V, 2, 2 * K>(t, S, ld, rows, bn, bstride, nb, on, ostride);
      break;
    case 1:
      blend_group<Scalar, V, 1, 8>(t, S, ld, rows, bn, bstride, nb, on, ostride);
      break;
    default:
      break;
  }
}

// One dispatcher per precision: double for shape_batch into BodyBatch, float (twice the lanes per
// vector, half the bytes) for shape_batch into BodyBatchF.
SMPL_KERNEL_VARIANTS_WITH(template <typename Scalar>, blend_batch,
                          (const Scalar* t, const Scalar* S, Eigen::Index ld, Eigen::Index rows,
                           const Scalar* beta, Eigen::Index bstride, Eigen::Index nb,
                           Eigen::Index nbodies, Scalar* out, Eigen::Index ostride),
                          (t, S, ld, rows, beta, bstride, nb, nbodies, out, ostride))

// v += P[:, c0:c0+nc] * f[c0:c0+nc] for the double pose blend shapes (P column-major, leading
// dimension ld). Blocks of 512 rows (4 KB per column segment: long sequential runs that the
// hardware prefetchers follow), 4 columns per pass over the L1-resident block of v.
SMPL_KERNEL_BODY
void pose_blend_f64_body(const double* P, Eigen::Index ld, Eigen::Index rows, const double* f,
                         Eigen::Index c0, Eigen::Index nc, double* v) {
  constexpr Eigen::Index kBlock = 512;
  for (Eigen::Index r0 = 0; r0 < rows; r0 += kBlock) {
    const Eigen::Index n = std::min(kBlock, rows - r0);
    double* o = v + r0;
    Eigen::Index c = c0;
    for (; c + 4 <= c0 + nc; c += 4) {
      const double* p0 = P + c * ld + r0;
      const double* p1 = p0 + ld;
      const double* p2 = p1 + ld;
      const double* p3 = p2 + ld;
      const double f0 = f[c], f1 = f[c + 1], f2 = f[c + 2], f3 = f[c + 3];
      for (Eigen::Index i = 0; i < n; ++i) {
        o[i] += (f0 * p0[i] + f1 * p1[i]) + (f2 * p2[i] + f3 * p3[i]);
      }
    }
    for (; c < c0 + nc; ++c) {
      const double* p0 = P + c * ld + r0;
      const double f0 = f[c];
      for (Eigen::Index i = 0; i < n; ++i) o[i] += f0 * p0[i];
    }
  }
}
SMPL_KERNEL_VARIANTS(pose_blend_f64,
                     (const double* P, Eigen::Index ld, Eigen::Index rows, const double* f,
                      Eigen::Index c0, Eigen::Index nc, double* v),
                     (P, ld, rows, f, c0, nc, v))

// Linear blend skinning of every vertex: out_v = sum_e w_e A_{j_e} [x_v; 1] + translation, with
// the weights as compressed sparse rows (outer, inner, values; nnz per row may be given for
// uncompressed matrices) and A as K row-major 3 x 4 blocks of 12 contiguous doubles.
SMPL_KERNEL_BODY
void skin_body(const double* A, const int* outer, const int* nnz, const int* inner,
               const double* values, Eigen::Index V, const double* x, const double* translation,
               double* out) {
  // Each 3 x 4 row is one vector of 4 doubles (GCC/Clang vector extension: one AVX2 register,
  // two SSE2 registers in the baseline build), so an influence costs 3 vector multiply-adds.
  static_assert(kVecBytes >= 16, "vector width");
  typedef double Row4 __attribute__((vector_size(32)));
  for (Eigen::Index v = 0; v < V; ++v) {
    Row4 t0 = {0, 0, 0, 0}, t1 = t0, t2 = t0;
    const int begin = outer[v];
    const int end = nnz ? begin + nnz[v] : outer[v + 1];
    for (int e = begin; e < end; ++e) {
      const double w = values[e];
      Row4 a0, a1, a2;
      const double* a = A + 12 * static_cast<Eigen::Index>(inner[e]);
      std::memcpy(&a0, a, sizeof a0);
      std::memcpy(&a1, a + 4, sizeof a1);
      std::memcpy(&a2, a + 8, sizeof a2);
      t0 += w * a0;
      t1 += w * a1;
      t2 += w * a2;
    }
    // x may be out (in-place skinning of a batch): read the vertex before writing it.
    const double p0 = x[3 * v], p1 = x[3 * v + 1], p2 = x[3 * v + 2];
    double* o = out + 3 * v;
    o[0] = t0[0] * p0 + t0[1] * p1 + t0[2] * p2 + t0[3] + translation[0];
    o[1] = t1[0] * p0 + t1[1] * p1 + t1[2] * p2 + t1[3] + translation[1];
    o[2] = t2[0] * p0 + t2[1] * p1 + t2[2] * p2 + t2[3] + translation[2];
  }
}
SMPL_KERNEL_VARIANTS(skin,
                     (const double* A, const int* outer, const int* nnz, const int* inner,
                      const double* values, Eigen::Index V, const double* x,
                      const double* translation, double* out),
                     (A, outer, nnz, inner, values, V, x, translation, out))

// Single-precision pose blend shapes over one run of columns [c0, c0 + nc): float columns are
// summed per block of rows in float, then added to the double vertices.
SMPL_KERNEL_BODY
void pose_blend_f32_body(const float* P, Eigen::Index ld, Eigen::Index rows, const float* feature,
                         Eigen::Index c0, Eigen::Index nc, double* v) {
  constexpr Eigen::Index kBlock = 512;
  float acc[kBlock];
  for (Eigen::Index r0 = 0; r0 < rows; r0 += kBlock) {
    const Eigen::Index n = std::min(kBlock, rows - r0);
    for (Eigen::Index i = 0; i < n; ++i) acc[i] = 0.0f;
    for (Eigen::Index c = c0; c < c0 + nc; ++c) {
      const float f = feature[c];
      const float* col = P + c * ld + r0;
      for (Eigen::Index i = 0; i < n; ++i) acc[i] += f * col[i];
    }
    for (Eigen::Index i = 0; i < n; ++i) v[r0 + i] += static_cast<double>(acc[i]);
  }
}
SMPL_KERNEL_VARIANTS(pose_blend_f32,
                     (const float* P, Eigen::Index ld, Eigen::Index rows, const float* feature,
                      Eigen::Index c0, Eigen::Index nc, double* v),
                     (P, ld, rows, feature, c0, nc, v))

// ---- Batch kernels (evaluate_batch): a block of rows of posedirs is applied to every body of
// the batch while it is in cache. For each output the operations and their order are exactly
// those of pose_blend_f64 / pose_blend_f32 over the same runs of columns.

// One step of kRows = lanes of T rows for G bodies: acc_g = v_g[r..]; per run, per group of 4
// columns acc_g += (f0 p0 + f1 p1) + (f2 p2 + f3 p3), then single columns acc_g += f p.
template <typename T, int G>
inline __attribute__((always_inline)) void pose_step_f64(const double* P, Eigen::Index ld,
                                                         Eigen::Index r, Eigen::Index pr,
                                                         const double* F, Eigen::Index fstride,
                                                         const Eigen::Index* runs, int nruns,
                                                         double* v, Eigen::Index vstride) {
  T acc[G];
#pragma GCC unroll 8
  for (int g = 0; g < G; ++g) std::memcpy(&acc[g], v + g * vstride + r, sizeof(T));
  for (Eigen::Index run = 0; run < nruns; ++run) {
    const Eigen::Index c0 = runs[2 * run], end = c0 + runs[2 * run + 1];
    Eigen::Index c = c0;
    for (; c + 4 <= end; c += 4) {
      T p0, p1, p2, p3;
      std::memcpy(&p0, P + c * ld + pr, sizeof(T));
      std::memcpy(&p1, P + (c + 1) * ld + pr, sizeof(T));
      std::memcpy(&p2, P + (c + 2) * ld + pr, sizeof(T));
      std::memcpy(&p3, P + (c + 3) * ld + pr, sizeof(T));
#pragma GCC unroll 8
      for (int g = 0; g < G; ++g) {
        const double* f = F + g * fstride + c;
        acc[g] += (f[0] * p0 + f[1] * p1) + (f[2] * p2 + f[3] * p3);
      }
    }
    for (; c < end; ++c) {
      T p0;
      std::memcpy(&p0, P + c * ld + pr, sizeof(T));
#pragma GCC unroll 8
      for (int g = 0; g < G; ++g) acc[g] += F[g * fstride + c] * p0;
    }
  }
#pragma GCC unroll 8
  for (int g = 0; g < G; ++g) std::memcpy(v + g * vstride + r, &acc[g], sizeof(T));
}

// Float pose blend shapes for M vectors of T rows and G bodies: per run the products are summed
// in float from 0, then the float sum is added to the double vertex.
template <typename T, int G, int M = 1>
inline __attribute__((always_inline)) void pose_step_f32(const float* P, Eigen::Index ld,
                                                         Eigen::Index r, Eigen::Index pr,
                                                         const float* F, Eigen::Index fstride,
                                                         const Eigen::Index* runs, int nruns,
                                                         double* v, Eigen::Index vstride) {
  constexpr int kLanes = static_cast<int>(sizeof(T) / kFloatBytes);
  for (Eigen::Index run = 0; run < nruns; ++run) {
    const Eigen::Index c0 = runs[2 * run], end = c0 + runs[2 * run + 1];
    T acc[G][M];
#pragma GCC unroll 8
    for (int g = 0; g < G; ++g) {
#pragma GCC unroll 4
      for (int m = 0; m < M; ++m) acc[g][m] = T{} - T{};  // zeros of T, scalar or vector
    }
    for (Eigen::Index c = c0; c < end; ++c) {
      T p[M];
#pragma GCC unroll 4
      for (Eigen::Index m = 0; m < M; ++m)
        std::memcpy(&p[m], P + c * ld + pr + m * kLanes, sizeof(T));
#pragma GCC unroll 8
      for (int g = 0; g < G; ++g) {
        const float f = F[g * fstride + c];
#pragma GCC unroll 4
        for (int m = 0; m < M; ++m) acc[g][m] += f * p[m];
      }
    }
#pragma GCC unroll 8
    for (int g = 0; g < G; ++g) {
      float a[kLanes * M];
      std::memcpy(a, acc[g], sizeof(T) * M);
      double* o = v + g * vstride + r;
      for (int i = 0; i < kLanes * M; ++i) o[i] += static_cast<double>(a[i]);
    }
  }
}

// Below this many bodies the batch streams posedirs once per body with the single-body kernels
// (long sequential column runs, no packing), which compute each output with the same operations
// in the same order as the packed kernels.
constexpr Eigen::Index kMinPackedBatch = 4;

// Rows per block of posedirs: the block (all columns) stays in a 256 KB share of the L2 cache
// while every body passes over it.
inline Eigen::Index pose_block_rows(Eigen::Index cols, size_t scalar_bytes) {
  const Eigen::Index fit = static_cast<Eigen::Index>(
      (256 * size_t{1024}) / (std::max<Eigen::Index>(cols, 1) * scalar_bytes));
  return std::max<Eigen::Index>(64, fit / 64 * 64);
}

// Rows [r0, r1) of every body: v_n += P[:, runs] * F_n[runs], blocked. Each block of rows is first
// packed so that for every step of kLanes rows the run columns follow each other (step-major, then
// column, then lane): a step then reads one contiguous stretch instead of touching one page per
// column (207 pages at a 165 KB stride would miss the TLB on every load). The packed block stays
// in the L2 cache while every body passes over it. Rows past the last whole step use P directly.
template <int kVecBytes, typename S, int G, int kRowVecs>
inline __attribute__((always_inline)) void pose_batch_rows(
    const S* P, Eigen::Index ld, Eigen::Index r0, Eigen::Index r1, const S* F, Eigen::Index fstride,
    const Eigen::Index* runs, int nruns, Eigen::Index nbodies, double* v, Eigen::Index vstride) {
  static_assert(kRowVecs == 1 || !std::is_same_v<S, double>, "double steps take one vector");
  typedef typename Vec<S, kVecBytes>::type V;
  constexpr Eigen::Index kLanes =
      Eigen::Index{kVecBytes} * kRowVecs / static_cast<Eigen::Index>(sizeof(S));
  Eigen::Index cols = 0;
  for (Eigen::Index run = 0; run < nruns; ++run)
    cols = std::max(cols, runs[2 * run] + runs[2 * run + 1]);
  const Eigen::Index block = pose_block_rows(cols, sizeof(S));
  std::vector<S> packed(static_cast<size_t>(block * cols));
  for (Eigen::Index rb = r0; rb < r1; rb += block) {
    const Eigen::Index re = std::min(r1, rb + block);
    const Eigen::Index steps = (re - rb) / kLanes, rs = rb + steps * kLanes;
    for (Eigen::Index run = 0; run < nruns; ++run) {
      for (Eigen::Index c = runs[2 * run]; c < runs[2 * run] + runs[2 * run + 1]; ++c) {
        const S* col = P + c * ld + rb;
        for (Eigen::Index st = 0; st < steps; ++st) {
          std::memcpy(packed.data() + (st * cols + c) * kLanes, col + st * kLanes,
                      sizeof(S) * kLanes);
        }
      }
    }
    for (Eigen::Index n = 0; n < nbodies; n += G) {
      const Eigen::Index g = std::min<Eigen::Index>(G, nbodies - n);
      const S* f = F + n * fstride;
      double* o = v + n * vstride;
      if (g == G) {
        for (Eigen::Index st = 0; st < steps; ++st) {
          const S* base = packed.data() + st * cols * kLanes;
          if constexpr (std::is_same_v<S, double>)
            pose_step_f64<V, G>(base, kLanes, rb + st * kLanes, 0, f, fstride, runs, nruns, o,
                                vstride);
          else
            pose_step_f32<V, G, kRowVecs>(base, kLanes, rb + st * kLanes, 0, f, fstride, runs,
                                          nruns, o, vstride);
        }
        for (Eigen::Index r = rs; r < re; ++r) {
          if constexpr (std::is_same_v<S, double>)
            pose_step_f64<double, G>(P, ld, r, r, f, fstride, runs, nruns, o, vstride);
          else
            pose_step_f32<float, G>(P, ld, r, r, f, fstride, runs, nruns, o, vstride);
        }
      } else {
        for (Eigen::Index k = 0; k < g; ++k) {
          const S* fk = f + k * fstride;
          double* ok = o + k * vstride;
          for (Eigen::Index st = 0; st < steps; ++st) {
            const S* base = packed.data() + st * cols * kLanes;
            if constexpr (std::is_same_v<S, double>)
              pose_step_f64<V, 1>(base, kLanes, rb + st * kLanes, 0, fk, fstride, runs, nruns, ok,
                                  vstride);
            else
              pose_step_f32<V, 1, kRowVecs>(base, kLanes, rb + st * kLanes, 0, fk, fstride, runs,
                                            nruns, ok, vstride);
          }
          for (Eigen::Index r = rs; r < re; ++r) {
            if constexpr (std::is_same_v<S, double>)
              pose_step_f64<double, 1>(P, ld, r, r, fk, fstride, runs, nruns, ok, vstride);
            else
              pose_step_f32<float, 1>(P, ld, r, r, fk, fstride, runs, nruns, ok, vstride);
          }
        }
      }
    }
  }
}

// The batch kernels per scalar type of P and F: 4 bodies x kRowVecs vectors of rows per step.
#define SMPL_POSE_BATCH_KERNEL(name, S, kRowVecs)                                                  \
  SMPL_KERNEL_BODY                                                                                 \
  void name##_body(const S* P, Eigen::Index ld, Eigen::Index r0, Eigen::Index r1, const S* F,      \
                   Eigen::Index fstride, const Eigen::Index* runs, int nruns,                      \
                   Eigen::Index nbodies, double* v, Eigen::Index vstride) {                        \
    pose_batch_rows<kVecBytes, S, 4, kRowVecs>(P, ld, r0, r1, F, fstride, runs, nruns, nbodies, v, \
                                               vstride);                                           \
  }                                                                                                \
  SMPL_KERNEL_VARIANTS(name,                                                                       \
                       (const S* P, Eigen::Index ld, Eigen::Index r0, Eigen::Index r1, const S* F, \
                        Eigen::Index fstride, const Eigen::Index* runs, int nruns,                 \
                        Eigen::Index nbodies, double* v, Eigen::Index vstride),                    \
                       (P, ld, r0, r1, F, fstride, runs, nruns, nbodies, v, vstride))
SMPL_POSE_BATCH_KERNEL(pose_batch_f64, double, 1)  // double: 1 vector of rows per step
SMPL_POSE_BATCH_KERNEL(pose_batch_f32, float, 2)   // float: 2 vectors of rows per step
#undef SMPL_POSE_BATCH_KERNEL

void check_betas(const BodyModel& model, Eigen::Index n) {
  if (n > model.num_betas()) {
    throw std::invalid_argument("smpl::evaluate: " + std::to_string(n) +
                                " betas given but the model has only " +
                                std::to_string(model.num_betas()) +
                                " shape components; load it with more betas or pass fewer");
  }
}

// v_shaped = v_template + shapedirs[:, :n] * betas (missing betas are zero), then the joints.
void shaped_rest(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                 Vertices& v_shaped, Joints& joints) {
  check_betas(model, betas.size());
  const Eigen::Index V = model.v_template.rows();
  v_shaped.resize(V, 3);
  blend(model.v_template.data(), model.shapedirs.data(), model.shapedirs.rows(), 3 * V,
        betas.data(), betas.size(), v_shaped.data());
  // J = J_regressor * v_shaped, row by row over the sparse regressor (no temporaries).
  const Eigen::Index K = model.j_regressor.rows();
  joints.resize(K, 3);
  for (Eigen::Index k = 0; k < K; ++k) {
    Eigen::RowVector3d j = Eigen::RowVector3d::Zero();
    for (SparseMatrix::InnerIterator it(model.j_regressor, k); it; ++it) {
      j += it.value() * v_shaped.row(it.col());
    }
    joints.row(k) = j;
  }
}

// Rows per chunk of the map of rows each joint's pose blend shapes touch (Workspace).
constexpr Eigen::Index kPoseRowChunk = 64;

// The chunks [c, end) that joints [j0, j1) (0-based among the K - 1 with posedirs) touch: the
// next stretch of needed chunks at or after `c`, as [first, last); first == nchunks when none.
// Without a map (chunks == nullptr) every chunk is needed.
std::pair<Eigen::Index, Eigen::Index> next_stretch(const std::uint8_t* chunks, Eigen::Index nchunks,
                                                   int j0, int j1, Eigen::Index c) {
  if (chunks == nullptr) return {c, nchunks};
  const auto needed = [&](Eigen::Index x) {
    for (int j = j0; j < j1; ++j) {
      if (chunks[static_cast<size_t>(j) * static_cast<size_t>(nchunks) + static_cast<size_t>(x)])
        return true;
    }
    return false;
  };
  while (c < nchunks && !needed(c)) ++c;
  Eigen::Index e = c;
  while (e < nchunks && needed(e)) ++e;
  return {c, e};
}

// v += posedirs[:, cols] * feature[cols] for each run of consecutive joints that are rotated
// (without a map), or for each rotated joint over the stretches of rows it touches (with one).
template <typename Matrix, typename Vector>
void add_pose_blend_shapes(
    const Matrix& posedirs, const Vector& feature,
    const std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>>& rot,
    const std::uint8_t* chunks, Eigen::Map<Eigen::VectorXd>& v) {
  using Scalar = typename Matrix::Scalar;
  const int K = static_cast<int>(rot.size());
  const Eigen::Index rows = posedirs.rows();
  const Eigen::Index nchunks = (rows + kPoseRowChunk - 1) / kPoseRowChunk;
  int k = 1;
  while (k < K) {
    if (rot[static_cast<size_t>(k)].isIdentity(0.0)) {
      ++k;
      continue;
    }
    // with a map, joint by joint (each over the rows it touches); else a run of joints at once
    int end = k + 1;
    while (chunks == nullptr && end < K && !rot[static_cast<size_t>(end)].isIdentity(0.0)) ++end;
    const Eigen::Index c0 = 9 * Eigen::Index{k - 1}, nc = 9 * Eigen::Index{end - k};
    for (auto s = next_stretch(chunks, nchunks, k - 1, end - 1, 0); s.first < nchunks;
         s = next_stretch(chunks, nchunks, k - 1, end - 1, s.second)) {
      const Eigen::Index r0 = s.first * kPoseRowChunk;
      const Eigen::Index n = std::min(rows, s.second * kPoseRowChunk) - r0;
      if constexpr (std::is_same_v<Scalar, double>) {
        pose_blend_f64(posedirs.data() + r0, rows, n, feature.data(), c0, nc, v.data() + r0);
      } else {
        pose_blend_f32(posedirs.data() + r0, rows, n, feature.data(), c0, nc, v.data() + r0);
      }
    }
    k = end;
  }
}

// Steps 6-8 for one body: the kinematic chain from ws.rotations and the rest joints `rest` (K x 3
// row-major), then skinning of the K x 3 posed rest vertices `x` (which may be `out_vertices`:
// each vertex is read before it is written). Writes transforms (translation included), the
// posed joints (3K values) and the vertices.
void chain_and_skin(const BodyModel& model, const double* rest, const double* x,
                    const Eigen::Vector3d& translation, Workspace& ws,
                    std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>>& G,
                    double* out_vertices, double* out_joints) {
  const int K = model.num_joints();
  const auto Ks = static_cast<size_t>(K);
  // 6. Kinematic chain: G_0 = [R_0 | J_0], G_k = G_parent [R_k | J_k - J_parent].
  G.resize(Ks);
  ws.skinning.resize(Ks);
  for (int k = 0; k < K; ++k) {
    const auto ks = static_cast<size_t>(k);
    Eigen::Matrix4d local = Eigen::Matrix4d::Identity();
    local.topLeftCorner<3, 3>() = ws.rotations[ks];
    const int p = model.parents[ks];
    const Eigen::Vector3d jk = Eigen::Map<const Eigen::Vector3d>(rest + 3 * ks);
    if (p < 0) {
      local.topRightCorner<3, 1>() = jk;
      G[ks] = local;
    } else {
      local.topRightCorner<3, 1>() =
          jk - Eigen::Map<const Eigen::Vector3d>(rest + 3 * static_cast<size_t>(p));
      G[ks] = G[static_cast<size_t>(p)] * local;
    }
    // 7. Remove the rest pose: A_k = G_k * translation(-J_k).
    ws.skinning[ks] = G[ks];
    ws.skinning[ks].topRightCorner<3, 1>() -= G[ks].topLeftCorner<3, 3>() * jk;
  }

  // 8. Linear blend skinning, then the global translation.
  ws.skinning_3x4.resize(12 * Ks);
  for (size_t k = 0; k < Ks; ++k) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c)
        ws.skinning_3x4[12 * k + 4 * static_cast<size_t>(r) + static_cast<size_t>(c)] =
            ws.skinning[k](r, c);
    }
  }
  const SparseMatrix& W = model.weights;
  skin(ws.skinning_3x4.data(), W.outerIndexPtr(), W.innerNonZeroPtr(), W.innerIndexPtr(),
       W.valuePtr(), model.v_template.rows(), x, translation.data(), out_vertices);
  for (int k = 0; k < K; ++k) {
    auto& Gk = G[static_cast<size_t>(k)];
    Gk.topRightCorner<3, 1>() += translation;
    for (int i = 0; i < 3; ++i) out_joints[3 * k + i] = Gk(i, 3);
  }
}

// Local rotations of one body (identity for an empty pose) and, when the model has pose blend
// shapes, its P pose features (R_k - I)(row, col) at 9 (k - 1) + 3 row + col.
void rotations_and_features(const BodyModel& model, const double* pose, bool has_pose,
                            Eigen::Matrix3d* rot, double* feature) {
  const int K = model.num_joints();
  for (Eigen::Index k = 0; k < K; ++k) {
    rot[k] = has_pose ? rodrigues(Eigen::Map<const Eigen::Vector3d>(pose + 3 * k))
                      : Eigen::Matrix3d::Identity();
  }
  if (!model.has_pose_blend_shapes()) return;
  for (int k = 1; k < K; ++k) {
    const Eigen::Matrix3d d = rot[k] - Eigen::Matrix3d::Identity();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) feature[9 * (k - 1) + 3 * i + j] = d(i, j);
    }
  }
}

// The float copy of posedirs in ws, (re)made when it is missing or from another matrix.
void ensure_float_posedirs(const BodyModel& model, Workspace& ws) {
  if (ws.posedirs_f_source != model.posedirs.data() ||
      ws.posedirs_f.rows() != model.posedirs.rows() ||
      ws.posedirs_f.cols() != model.posedirs.cols()) {
    ws.posedirs_f = model.posedirs.cast<float>();
    ws.posedirs_f_source = model.posedirs.data();
  }
}

// The map of the 64-row chunks of posedirs each joint touches (Workspace::pose_row_chunks), or
// nullptr when the workspace skips nothing or every joint touches every chunk (SMPL's dense
// correctives: then the runs of joints and their arithmetic are those without a map).
const std::uint8_t* pose_row_map(const BodyModel& model, Workspace& ws) {
  if (!ws.skip_zero_pose_rows) return nullptr;
  if (ws.pose_row_chunks_source != model.posedirs.data() ||
      ws.pose_row_chunks_size != model.posedirs.size()) {
    const Eigen::Index rows = model.posedirs.rows(), joints = model.posedirs.cols() / 9;
    const Eigen::Index nchunks = (rows + kPoseRowChunk - 1) / kPoseRowChunk;
    ws.pose_row_chunks.assign(static_cast<size_t>(joints * nchunks), 0);
    for (Eigen::Index j = 0; j < joints; ++j) {
      std::uint8_t* mark = ws.pose_row_chunks.data() + j * nchunks;
      for (Eigen::Index c = 9 * j; c < 9 * j + 9; ++c) {
        const double* col = model.posedirs.data() + c * rows;
        for (Eigen::Index r = 0; r < rows; ++r) {
          if (col[r] != 0.0) mark[r / kPoseRowChunk] = 1;
        }
      }
    }
    if (std::find(ws.pose_row_chunks.begin(), ws.pose_row_chunks.end(), 0) ==
        ws.pose_row_chunks.end()) {
      ws.pose_row_chunks.clear();  // nothing to skip
    }
    ws.pose_row_chunks_source = model.posedirs.data();
    ws.pose_row_chunks_size = model.posedirs.size();
  }
  return ws.pose_row_chunks.empty() ? nullptr : ws.pose_row_chunks.data();
}

int resolve_threads(int threads, const char* who) {
  if (threads < 0) {
    throw std::invalid_argument(std::string(who) + ": threads is " + std::to_string(threads) +
                                ", expected 0 (one per core) or a positive count");
  }
  if (threads == 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return threads;
}

// Runs f(begin, end) on `threads` contiguous shares of [0, n), each on its own thread (the
// calling thread takes the first), with the caller's SIMD level; rethrows the first exception.
template <typename F>
void parallel_for(int threads, Eigen::Index n, const F& f) {
  const Eigen::Index t = std::max<Eigen::Index>(1, std::min<Eigen::Index>(threads, n));
  if (t <= 1) {
    f(Eigen::Index{0}, n);
    return;
  }
  const SimdLevel level = simd_level();
  std::vector<std::exception_ptr> errors(static_cast<size_t>(t));
  std::vector<std::thread> workers;
  auto share = [&](Eigen::Index i) {
    try {
      const ScopedSimdLevel pin(level);
      f(n * i / t, n * (i + 1) / t);
    } catch (...) {
      errors[static_cast<size_t>(i)] = std::current_exception();
    }
  };
  for (Eigen::Index i = 1; i < t; ++i) workers.emplace_back(share, i);
  share(0);
  for (auto& w : workers) w.join();
  for (auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

// shape() for bodies [n0, n1) of a batch, blocked over vertices: each block of shapedirs rows is
// applied to every body, then the joint regressor's entries of that block of vertices are added
// (per joint in the regressor's storage order, as in shaped_rest; summed in double). Scalar is the
// precision of the template `t` (V x 3 row-major), `shapedirs` (3V x nb columns, leading dimension
// ld) and the outputs: double (BodyBatch, the model's own arrays) or float (BodyBatchF, the
// workspace's float copies).
template <typename Scalar, typename Out>
void shape_rows(const BodyModel& model, const Scalar* t, const Scalar* shapedirs, Eigen::Index ld,
                const Scalar* beta, Eigen::Index bstride, Eigen::Index nb, Eigen::Index n0,
                Eigen::Index n1, Out& vertices, Out& joints) {
  const Eigen::Index V = model.v_template.rows();
  const Eigen::Index K = model.j_regressor.rows();
  const SparseMatrix& J = model.j_regressor;
  // Vertices per block: the block of shapedirs (3 x 8 bytes x nb per vertex in double) within
  // 24 KB, so that it stays in the L1 cache while every group of 4 bodies passes over it.
  const Eigen::Index block = std::max<Eigen::Index>(
      32, (24 * Eigen::Index{1024}) / (24 * std::max<Eigen::Index>(nb, 1)) / 32 * 32);
  std::vector<Eigen::Index> cursor(static_cast<size_t>(K)), end(static_cast<size_t>(K));
  for (Eigen::Index k = 0; k < K; ++k) {
    cursor[static_cast<size_t>(k)] = J.outerIndexPtr()[k];
    end[static_cast<size_t>(k)] = J.innerNonZeroPtr()
                                      ? cursor[static_cast<size_t>(k)] + J.innerNonZeroPtr()[k]
                                      : J.outerIndexPtr()[k + 1];
  }
  for (Eigen::Index n = n0; n < n1; ++n) joints.row(n).setZero();
  const int* inner = J.innerIndexPtr();
  const double* value = J.valuePtr();
  for (Eigen::Index v0 = 0; v0 < V; v0 += block) {
    const Eigen::Index v1 = std::min(V, v0 + block);
    if (n1 > n0) {
      blend_batch(t + 3 * v0, shapedirs + 3 * v0, ld, 3 * (v1 - v0), beta + n0 * bstride, bstride,
                  nb, n1 - n0, vertices.row(n0).data() + 3 * v0, vertices.outerStride());
    }
    for (Eigen::Index k = 0; k < K; ++k) {
      const Eigen::Index lo = cursor[static_cast<size_t>(k)];
      Eigen::Index hi = lo;
      while (hi < end[static_cast<size_t>(k)] && inner[hi] < v1) ++hi;
      cursor[static_cast<size_t>(k)] = hi;
      if (hi == lo) continue;
      for (Eigen::Index n = n0; n < n1; ++n) {
        Scalar* j = joints.row(n).data() + 3 * k;
        const Scalar* x = vertices.row(n).data();
        double j0 = j[0], j1 = j[1], j2 = j[2];
        for (Eigen::Index e = lo; e < hi; ++e) {
          const double w = value[e];
          const Scalar* xv = x + 3 * static_cast<Eigen::Index>(inner[e]);
          j0 += w * xv[0];
          j1 += w * xv[1];
          j2 += w * xv[2];
        }
        j[0] = static_cast<Scalar>(j0);
        j[1] = static_cast<Scalar>(j1);
        j[2] = static_cast<Scalar>(j2);
      }
    }
  }
}

// shape_rows on the model's own (double) template and shapedirs.
void shape_rows(const BodyModel& model, const Eigen::Ref<const RowMatrixXd>& betas, Eigen::Index n0,
                Eigen::Index n1, RowMatrixXd& vertices, RowMatrixXd& joints) {
  shape_rows(model, model.v_template.data(), model.shapedirs.data(), model.shapedirs.rows(),
             betas.data(), betas.outerStride(), betas.cols(), n0, n1, vertices, joints);
}

// The float copies of v_template and shapedirs in ws, (re)made when missing or from another model.
void ensure_float_shapedirs(const BodyModel& model, Workspace& ws) {
  if (ws.shapedirs_f_source != model.shapedirs.data() ||
      ws.shapedirs_f.rows() != model.shapedirs.rows() ||
      ws.shapedirs_f.cols() != model.shapedirs.cols() ||
      ws.v_template_f.rows() != model.v_template.rows()) {
    ws.shapedirs_f = model.shapedirs.cast<float>();
    ws.v_template_f = model.v_template.cast<float>();
    ws.shapedirs_f_source = model.shapedirs.data();
  }
}

}  // namespace

Eigen::Matrix3d rodrigues(const Eigen::Vector3d& r) {
  const double t2 = r.squaredNorm();
  const double t = std::sqrt(t2);
  double a, b;  // R = I + a K + b K^2, a = sin t / t, b = (1 - cos t) / t^2
  if (t < kSmallAngle) {
    a = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0);
    b = 0.5 * (1.0 - t2 / 12.0 * (1.0 - t2 / 30.0));
  } else {
    const double s = std::sin(0.5 * t);
    a = std::sin(t) / t;
    b = 2.0 * s * s / t2;
  }
  Eigen::Matrix3d K;
  K << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity() + a * K + b * (K * K);
  return R;
}

void shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas, Body& out) {
  shaped_rest(model, betas, out.vertices, out.joints);
  const auto K = static_cast<size_t>(model.num_joints());
  out.transforms.resize(K);
  for (size_t k = 0; k < K; ++k) {
    out.transforms[k].setIdentity();
    out.transforms[k].topRightCorner<3, 1>() =
        out.joints.row(static_cast<Eigen::Index>(k)).transpose();
  }
}

Body shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas) {
  Body body;
  shape(model, betas, body);
  return body;
}

void evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose, const Eigen::Vector3d& translation,
              Workspace& ws, Body& out) {
  const int K = model.num_joints();
  if (pose.size() != 0 && pose.size() != 3 * Eigen::Index{K}) {
    throw std::invalid_argument("smpl::evaluate: pose has " + std::to_string(pose.size()) +
                                " values, expected 0 (rest pose) or 3 x " + std::to_string(K) +
                                " = " + std::to_string(3 * K) + " axis-angle values");
  }
  // 1-2. Shape blend shapes and joint regression.
  shaped_rest(model, betas, ws.v_shaped, ws.rest_joints);
  const Eigen::Index V = ws.v_shaped.rows();

  // 3-4. Local rotations and pose features: feature 9 (k - 1) + 3 row + col = (R_k - I)(row, col).
  const auto Ks = static_cast<size_t>(K);
  ws.rotations.resize(Ks);
  ws.pose_feature.resize(model.num_pose_features());
  rotations_and_features(model, pose.data(), pose.size() != 0, ws.rotations.data(),
                         ws.pose_feature.data());

  // 5. Pose blend shapes.
  if (model.has_pose_blend_shapes()) {
    const Eigen::Index P = model.num_pose_features();
    Eigen::Map<Eigen::VectorXd> flat(ws.v_shaped.data(), 3 * V);
    const std::uint8_t* chunks = pose_row_map(model, ws);
    if (ws.single_precision_pose_blend_shapes) {
      ensure_float_posedirs(model, ws);
      ws.pose_feature_f.resize(P);
      ws.pose_feature_f = ws.pose_feature.cast<float>();
      add_pose_blend_shapes(ws.posedirs_f, ws.pose_feature_f, ws.rotations, chunks, flat);
    } else {
      add_pose_blend_shapes(model.posedirs, ws.pose_feature, ws.rotations, chunks, flat);
    }
  }

  // 6-8. Kinematic chain, skinning, translation.
  out.vertices.resize(V, 3);
  out.joints.resize(K, 3);
  chain_and_skin(model, ws.rest_joints.data(), ws.v_shaped.data(), translation, ws, out.transforms,
                 out.vertices.data(), out.joints.data());
}

Body evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose, const Eigen::Vector3d& translation) {
  Workspace ws;
  ws.skip_zero_pose_rows = false;  // one body: the map's pass would cost more than it saves
  Body body;
  evaluate(model, betas, pose, translation, ws, body);
  return body;
}

void shape_batch(const BodyModel& model, const Eigen::Ref<const RowMatrixXd>& betas, BodyBatch& out,
                 int threads) {
  threads = resolve_threads(threads, "smpl::shape_batch");
  check_betas(model, betas.cols());
  const Eigen::Index N = betas.rows();
  out.vertices.resize(N, 3 * model.v_template.rows());
  out.joints.resize(N, 3 * model.j_regressor.rows());
  parallel_for(threads, N, [&](Eigen::Index n0, Eigen::Index n1) {
    shape_rows(model, betas, n0, n1, out.vertices, out.joints);
  });
}

void shape_batch(const BodyModel& model, const Eigen::Ref<const RowMatrixXd>& betas, Workspace& ws,
                 BodyBatchF& out, int threads) {
  threads = resolve_threads(threads, "smpl::shape_batch");
  check_betas(model, betas.cols());
  ensure_float_shapedirs(model, ws);
  const Eigen::Index N = betas.rows();
  out.vertices.resize(N, 3 * model.v_template.rows());
  out.joints.resize(N, 3 * model.j_regressor.rows());
  ws.betas_f = betas.cast<float>();  // reuses ws's buffer when the batch has the same size
  parallel_for(threads, N, [&](Eigen::Index n0, Eigen::Index n1) {
    shape_rows(model, ws.v_template_f.data(), ws.shapedirs_f.data(), ws.shapedirs_f.rows(),
               ws.betas_f.data(), ws.betas_f.outerStride(), ws.betas_f.cols(), n0, n1, out.vertices,
               out.joints);
  });
}

namespace {

// The shapes of evaluate_batch's poses and translations against N bodies of K joints.
void check_batch_inputs(const Eigen::Ref<const RowMatrixXd>& poses,
                        const Eigen::Ref<const RowMatrixXd>& translations, Eigen::Index N, int K) {
  const bool has_pose = poses.cols() != 0;
  if (has_pose && poses.cols() != 3 * Eigen::Index{K}) {
    throw std::invalid_argument("smpl::evaluate_batch: poses have " + std::to_string(poses.cols()) +
                                " columns, expected 0 (rest pose) "
                                "or 3 x " +
                                std::to_string(K) + " = " + std::to_string(3 * K) +
                                " axis-angle values per body");
  }
  if (poses.rows() != N && !(poses.cols() == 0 && poses.rows() == 0)) {
    throw std::invalid_argument("smpl::evaluate_batch: " + std::to_string(N) +
                                " rows of betas but " + std::to_string(poses.rows()) +
                                " rows of poses; give one row per body");
  }
  if (!((translations.rows() == 0) || (translations.rows() == N && translations.cols() == 3))) {
    throw std::invalid_argument("smpl::evaluate_batch: translations are " +
                                std::to_string(translations.rows()) + " x " +
                                std::to_string(translations.cols()) + ", expected " +
                                std::to_string(N) + " x 3 metres or 0 rows (no translation)");
  }
}

// The pose feature columns to blend, as (first column, count) pairs: the runs of joints (from 1)
// rotated in any of the N bodies (rot: N x K rotations).
std::vector<Eigen::Index> rotated_runs(
    const std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>>& rot,
    Eigen::Index N, int K) {
  std::vector<Eigen::Index> runs;
  int k = 1;
  auto rotated = [&](int j) {
    for (Eigen::Index n = 0; n < N; ++n) {
      if (!rot[static_cast<size_t>(n * K + j)].isIdentity(0.0)) return true;
    }
    return false;
  };
  while (k < K) {
    if (!rotated(k)) {
      ++k;
      continue;
    }
    int e = k + 1;
    while (e < K && rotated(e)) ++e;
    runs.push_back(9 * Eigen::Index{k - 1});
    runs.push_back(9 * Eigen::Index{e - k});
    k = e;
  }
  return runs;
}

// 5. Pose blend shapes of every body at once per block of rows, added to out.vertices.
void batch_pose_blend(const BodyModel& model, const RowMatrixXd& feature,
                      const std::vector<Eigen::Index>& runs, int threads, Workspace& ws,
                      BodyBatch& out) {
  const Eigen::Index N = feature.rows(), P = feature.cols();
  const Eigen::Index V = model.v_template.rows();
  const int nruns = static_cast<int>(runs.size() / 2);
  if (nruns > 0) {
    const Eigen::Index rows = 3 * V;
    const Eigen::Index t = std::max<Eigen::Index>(1, std::min<Eigen::Index>(threads, rows / 64));
    // Every block of rows with the kernels of the pose blend shapes' scalar type: body by body
    // below kMinPackedBatch bodies, else the packed batch kernel.
    // The 64-row chunks any run's joints touch (all without the workspace's map): the others
    // add exact zeros and are skipped.
    static_assert(kPoseRowChunk == 64, "the blocks below are the map's chunks");
    const Eigen::Index nchunks = (rows + kPoseRowChunk - 1) / kPoseRowChunk;
    std::vector<std::uint8_t> needed(static_cast<size_t>(nchunks), 1);
    if (const std::uint8_t* chunks = pose_row_map(model, ws)) {
      std::fill(needed.begin(), needed.end(), 0);
      for (Eigen::Index run = 0; run < nruns; ++run) {
        const int j0 = static_cast<int>(runs[2 * run] / 9);
        const int j1 = static_cast<int>((runs[2 * run] + runs[2 * run + 1]) / 9);
        for (auto s = next_stretch(chunks, nchunks, j0, j1, 0); s.first < nchunks;
             s = next_stretch(chunks, nchunks, j0, j1, s.second)) {
          std::fill(needed.begin() + s.first, needed.begin() + s.second, 1);
        }
      }
    }
    const auto blend_blocks = [&](const auto* posedirs, const auto& f, auto blend, auto batch) {
      parallel_for(static_cast<int>(t), nchunks, [&](Eigen::Index b0, Eigen::Index b1) {
        for (Eigen::Index c = b0; c < b1;) {
          if (needed[static_cast<size_t>(c)] == 0) {
            ++c;
            continue;
          }
          Eigen::Index e = c + 1;
          while (e < b1 && needed[static_cast<size_t>(e)] != 0) ++e;
          const Eigen::Index r0 = std::min(rows, 64 * c), r1 = std::min(rows, 64 * e);
          c = e;
          if (N < kMinPackedBatch) {
            for (Eigen::Index n = 0; n < N; ++n) {
              for (Eigen::Index run = 0; run < nruns; ++run) {
                blend(posedirs + r0, rows, r1 - r0, f.row(n).data(), runs[2 * run],
                      runs[2 * run + 1], out.vertices.row(n).data() + r0);
              }
            }
            continue;
          }
          batch(posedirs, rows, r0, r1, f.data(), P, runs.data(), nruns, N, out.vertices.data(),
                3 * V);
        }
      });
    };
    if (ws.single_precision_pose_blend_shapes) {
      ensure_float_posedirs(model, ws);
      const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> ff =
          feature.cast<float>();
      blend_blocks(ws.posedirs_f.data(), ff, pose_blend_f32, pose_batch_f32);
    } else {
      blend_blocks(model.posedirs.data(), feature, pose_blend_f64, pose_batch_f64);
    }
  }
}

}  // namespace

void evaluate_batch(const BodyModel& model, const Eigen::Ref<const RowMatrixXd>& betas,
                    const Eigen::Ref<const RowMatrixXd>& poses,
                    const Eigen::Ref<const RowMatrixXd>& translations, Workspace& ws,
                    BodyBatch& out, int threads) {
  threads = resolve_threads(threads, "smpl::evaluate_batch");
  check_betas(model, betas.cols());
  const Eigen::Index N = betas.rows();
  const int K = model.num_joints();
  const Eigen::Index V = model.v_template.rows(), P = model.num_pose_features();
  const bool has_pose = poses.cols() != 0;
  check_batch_inputs(poses, translations, N, K);
  out.vertices.resize(N, 3 * V);
  out.joints.resize(N, 3 * Eigen::Index{K});
  // Rotations and pose features of every body; vertices and rest joints of every body.
  std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>> rot(
      static_cast<size_t>(N * K));
  RowMatrixXd feature(N, P);
  parallel_for(threads, N, [&](Eigen::Index n0, Eigen::Index n1) {
    shape_rows(model, betas, n0, n1, out.vertices, out.joints);
    for (Eigen::Index n = n0; n < n1; ++n) {
      rotations_and_features(model, has_pose ? poses.row(n).data() : nullptr, has_pose,
                             rot.data() + n * K, feature.row(n).data());
    }
  });

  // 5. Pose blend shapes: the runs of joints rotated in any body, every body at once per block.
  if (model.has_pose_blend_shapes() && N > 0) {
    std::vector<Eigen::Index> runs = rotated_runs(rot, N, K);
    if (pose_row_map(model, ws) != nullptr) {  // joint by joint, as evaluate() then does
      std::vector<Eigen::Index> split;
      for (size_t r = 0; r + 1 < runs.size(); r += 2) {
        for (Eigen::Index c = runs[r]; c < runs[r] + runs[r + 1]; c += 9) {
          split.push_back(c);
          split.push_back(9);
        }
      }
      runs = std::move(split);
    }
    batch_pose_blend(model, feature, runs, threads, ws, out);
  }

  // 6-8. Chain and skinning, in place, per body.
  parallel_for(threads, N, [&](Eigen::Index n0, Eigen::Index n1) {
    Workspace local;
    std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> G;
    Eigen::VectorXd rest(3 * K);
    local.rotations.resize(static_cast<size_t>(K));
    for (Eigen::Index n = n0; n < n1; ++n) {
      std::copy(rot.begin() + n * K, rot.begin() + (n + 1) * K, local.rotations.begin());
      rest = out.joints.row(n).transpose();
      const Eigen::Vector3d tr = translations.rows() == 0
                                     ? Eigen::Vector3d::Zero()
                                     : Eigen::Vector3d(translations.row(n).transpose());
      double* x = out.vertices.row(n).data();
      chain_and_skin(model, rest.data(), x, tr, local, G, x, out.joints.row(n).data());
    }
  });
}

}  // namespace smpl
