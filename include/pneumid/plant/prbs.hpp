// Maximal-length binary sequences (m-sequences) from a linear feedback shift
// register, the PRBS of system identification.
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999,
//     section 13.3 (pseudo-random binary sequences).
// [2] Taps as in scipy.signal.max_len_seq (first entry per order of the
//     New Wave Instruments table), so that sequences can be checked against it:
//     register s[0..n-1], index i; output s[i]; s[i] <- s[i] xor s[(i+tap) mod n]
//     for each tap; i <- (i + 1) mod n.
#pragma once

#include <cstdint>
#include <vector>

namespace pneumid {

/// Feedback taps of the maximal-length LFSR of the given order (2..32).
/// @throws InvalidArgument for an order outside 2..32.
const std::vector<int>& PrbsTaps(int order);

/// Incremental m-sequence generator; period 2^order - 1.
class MaxLengthSequenceGenerator {
 public:
  /// `seed`: initial register, bit i of seed -> cell i; must be in 1..2^order-1.
  /// @throws InvalidArgument for a bad order or seed.
  MaxLengthSequenceGenerator(int order, std::uint64_t seed);
  /// Next bit (0 or 1).
  std::uint8_t Next();
  int order() const { return order_; }  ///< register length n (2..32)
  /// 2^order - 1.
  std::uint64_t period() const { return (std::uint64_t{1} << order_) - 1; }

 private:
  int order_;
  std::vector<int> taps_;
  std::vector<std::uint8_t> state_;
  int idx_ = 0;
};

/// Bit `k` (0-based) of the m-sequence of the given order and seed, without
/// generating the k bits before it: the outputs obey b[k+n] = b[k] xor
/// b[k+tap]... (n = order), so b[k] is the combination of the seed bits given
/// by x^k mod (x^n + sum x^tap + 1) over GF(2), in O(n log k) operations.
/// @throws InvalidArgument for a bad order or seed.
std::uint8_t MaxLengthSequenceBit(int order, std::uint64_t seed, std::uint64_t k);

/// The first `length` bits (default: one full period, which must then fit in
/// memory, order <= 28) of the m-sequence of the given order and seed.
/// @throws InvalidArgument for a bad order, seed or length.
std::vector<std::uint8_t> MaxLengthSequence(int order, std::uint64_t seed,
                                            std::int64_t length = -1);

}  // namespace pneumid
