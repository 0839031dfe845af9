// Maximal-length binary sequences (see include/pneumid/plant/prbs.hpp).
#include "pneumid/plant/prbs.hpp"

#include <map>

#include "pneumid/common/check.hpp"

namespace pneumid {

const std::vector<int>& PrbsTaps(int order) {
  static const std::map<int, std::vector<int>> taps = {
      {2, {1}},           {3, {2}},           {4, {3}},           {5, {3}},
      {6, {5}},           {7, {6}},           {8, {7, 6, 1}},     {9, {5}},
      {10, {7}},          {11, {9}},          {12, {11, 10, 4}},  {13, {12, 11, 8}},
      {14, {13, 12, 2}},  {15, {14}},         {16, {15, 13, 4}},  {17, {14}},
      {18, {11}},         {19, {18, 17, 14}}, {20, {17}},         {21, {19}},
      {22, {21}},         {23, {18}},         {24, {23, 22, 17}}, {25, {22}},
      {26, {25, 24, 20}}, {27, {26, 25, 22}}, {28, {25}},         {29, {27}},
      {30, {29, 28, 7}},  {31, {28}},         {32, {31, 30, 10}}};
  auto it = taps.find(order);
  PNEUMID_CHECK(it != taps.end(), "PRBS order must be in 2..32, got {}", order);
  return it->second;
}

MaxLengthSequenceGenerator::MaxLengthSequenceGenerator(int order, std::uint64_t seed)
    : order_(order), taps_(PrbsTaps(order)), state_(static_cast<std::size_t>(order)) {
  const std::uint64_t max_seed = (std::uint64_t{1} << order) - 1;
  PNEUMID_CHECK(seed >= 1 && seed <= max_seed,
                "PRBS seed must be in 1..2^order-1 = {} (a non-zero register), got {}", max_seed,
                seed);
  for (int i = 0; i < order; ++i) state_[static_cast<std::size_t>(i)] = (seed >> i) & 1u;
}

std::uint8_t MaxLengthSequenceGenerator::Next() {
  std::uint8_t feedback = state_[static_cast<std::size_t>(idx_)];
  const std::uint8_t out = feedback;
  for (int tap : taps_) feedback ^= state_[static_cast<std::size_t>((tap + idx_) % order_)];
  state_[static_cast<std::size_t>(idx_)] = feedback;
  idx_ = (idx_ + 1) % order_;
  return out;
}

std::uint8_t MaxLengthSequenceBit(int order, std::uint64_t seed, std::uint64_t k) {
  const MaxLengthSequenceGenerator check(order, seed);  // validates order and seed
  // Polynomials over GF(2) as bit masks; P(x) = x^n + sum_tap x^tap + 1.
  const int n = order;
  std::uint64_t low = 1;  // P without its leading term x^n
  for (int tap : PrbsTaps(order)) low ^= std::uint64_t{1} << tap;
  const std::uint64_t top = std::uint64_t{1} << (n - 1);
  const std::uint64_t mask = (std::uint64_t{1} << n) - 1;  // n <= 32
  // a * b mod P for a, b of degree < n.
  const auto mul = [&](std::uint64_t a, std::uint64_t b) {
    std::uint64_t r = 0;
    for (int i = n - 1; i >= 0; --i) {
      const bool carry = (r & top) != 0;
      r = (r << 1) & mask;
      if (carry) r ^= low;
      if ((b >> i) & 1u) r ^= a;
    }
    return r;
  };
  std::uint64_t result = 1;  // x^0
  std::uint64_t base = 2;    // x (n >= 2)
  for (std::uint64_t e = k; e != 0; e >>= 1) {
    if (e & 1u) result = mul(result, base);
    base = mul(base, base);
  }
  // b[k] = sum_i c_i b[i], and b[0..n-1] are the seed bits.
  return static_cast<std::uint8_t>(__builtin_parityll(result & seed));
}

std::vector<std::uint8_t> MaxLengthSequence(int order, std::uint64_t seed, std::int64_t length) {
  MaxLengthSequenceGenerator gen(order, seed);
  if (length < 0) {
    PNEUMID_CHECK(order <= 28,
                  "a full PRBS period of order {} does not fit in memory; give a length", order);
    length = static_cast<std::int64_t>(gen.period());
  }
  std::vector<std::uint8_t> bits(static_cast<std::size_t>(length));
  for (auto& b : bits) b = gen.Next();
  return bits;
}

}  // namespace pneumid
