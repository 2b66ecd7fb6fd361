// Allocation-free per-frame evaluation: this test binary replaces malloc and friends with
// counting wrappers around glibc's own allocator (__libc_malloc, ...), so every heap allocation
// (operator new, Eigen's aligned_malloc, std::vector) is counted. Its own executable, so no other
// test runs with the replaced allocator. Under AddressSanitizer the sanitizer owns malloc: the
// counting test is skipped there and the pointer-stability test in test_evaluate.cpp still runs.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>

#include "caliper_test/random_model.hpp"
#include "smpl/evaluate.hpp"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CALIPER_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define CALIPER_COUNT_ALLOCATIONS 0
#endif
#endif
#if !defined(CALIPER_COUNT_ALLOCATIONS) && defined(__GLIBC__)
#define CALIPER_COUNT_ALLOCATIONS 1
#endif
#ifndef CALIPER_COUNT_ALLOCATIONS
#define CALIPER_COUNT_ALLOCATIONS 0
#endif

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

#if CALIPER_COUNT_ALLOCATIONS
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void* memalign(std::size_t alignment, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = __libc_memalign(alignment, n);
  if (!p) return 12;  // ENOMEM
  *out = p;
  return 0;
}
void free(void* p) {
  __libc_free(p);
}
}
#endif

namespace {

TEST(EvaluateAllocations, CounterSeesAllocations) {
  if (!CALIPER_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocations are not counted under sanitizers";
  const long before = g_allocations.load();
  auto* v = new std::vector<double>(1000);  // must be counted, or the next test proves nothing
  const long after = g_allocations.load();
  delete v;
  EXPECT_GE(after - before, 2);
  Eigen::VectorXd x(1000);
  x.setZero();
  EXPECT_GE(g_allocations.load() - after, 1);
}

TEST(EvaluateAllocations, WorkspaceEvaluationAllocatesNothingAfterFirstUse) {
  if (!CALIPER_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocations are not counted under sanitizers";
  const auto m = caliper::test::make_random_model(10, 24, true, 5);
  const Eigen::VectorXd betas = caliper::test::random_betas(10, 1.0, 6);
  const Eigen::VectorXd short_betas = caliper::test::random_betas(3, 1.0, 7);
  const Eigen::VectorXd pose = caliper::test::random_pose(24, 1.5, 8);
  Eigen::VectorXd sparse_pose = pose;
  sparse_pose.segment<18>(9).setZero();
  for (bool single : {false, true}) {
    smpl::Workspace ws;
    ws.single_precision_pose_blend_shapes = single;
    smpl::Body body, rest;
    smpl::evaluate(m, betas, pose, Eigen::Vector3d::Zero(), ws, body);  // sizes everything
    smpl::shape(m, betas, rest);
    const long before = g_allocations.load();
    for (int i = 0; i < 3; ++i) {
      smpl::evaluate(m, betas, pose, Eigen::Vector3d(0, i, 0), ws, body);
      smpl::evaluate(m, short_betas, sparse_pose, Eigen::Vector3d::Zero(), ws, body);
      smpl::evaluate(m, betas, Eigen::VectorXd(), Eigen::Vector3d::Zero(), ws, body);
      smpl::shape(m, short_betas, rest);
    }
    EXPECT_EQ(g_allocations.load() - before, 0) << (single ? "float" : "double") << " path";
  }
}

}  // namespace
