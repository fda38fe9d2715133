

#include "io/las/laz_arithmetic.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <vector>

namespace pointrast::io::laz {

POINTRAST_LAZ_NO_COVERAGE void BitModel::update() {
  // Halve the counts when they reach the maximum, so the model keeps adapting.
  if ((bitCount += updateCycle) > kBitMaxCount) {
    bitCount = (bitCount + 1) >> 1;
    bit0Count = (bit0Count + 1) >> 1;
    if (bit0Count == bitCount) ++bitCount;
  }
  const uint32_t scale = 0x80000000u / bitCount;
  bit0Prob = (bit0Count * scale) >> (31 - kBitLengthShift);
  updateCycle = std::min<uint32_t>((5 * updateCycle) >> 2, 64);
  bitsUntilUpdate = updateCycle;
}

POINTRAST_LAZ_NO_COVERAGE void SymbolModel::create(uint32_t symbols, ModelUse use) {
  assert(symbols >= 2 && symbols <= 2048);
  symbols_ = symbols;
  lastSymbol_ = symbols - 1;
  size_t words = 2 * size_t(symbols);
  const bool table = use == ModelUse::Decode;
  if (table) {
    // A table of four entries per symbol up to 2^10 entries, and at least one per symbol: FastAC
    // sizes it for four symbols per entry, and gives none to alphabets of 16 or fewer, but the
    // bisection within an entry (or over the whole small alphabet) mispredicts, and a finer table
    // costs nothing in exactness (it only narrows the search; the distribution decides). Each update
    // refills the table, so a finer one costs instructions there.
    uint32_t tableBits = 3;
    while (symbols > (1u << tableBits) || (4 * symbols > (1u << tableBits) && tableBits < 10))
      ++tableBits;
    tableSize_ = 1u << tableBits;
    tableShift_ = kLengthShift - tableBits;
    words += tableSize_ + 4; // entries 0..tableSize + 1, and two that update() may write and drop
  } else {
    tableSize_ = tableShift_ = 0;
  }
  storage_ = std::make_unique<uint32_t[]>(words);
  distribution_ = storage_.get();
  symbolCount_ = distribution_ + symbols;
  decoderTable_ = table ? symbolCount_ + symbols : nullptr;
  ready_ = false;
}

POINTRAST_LAZ_NO_COVERAGE void SymbolModel::reset() {
  assert(symbols_ != 0);
  // Every reset of an alphabet of a given size ends in the same tables (counts of 1, their
  // distribution and decoder table): the first on a thread computes them, later ones copy them. A
  // chunk resets a model per context it meets, often hundreds of 256-symbol models. An encoder's model
  // copies the distribution and counts only (the words before the decoder table); a decoder's model
  // after an encoder's computes them again, with its table.
  thread_local std::vector<std::vector<uint32_t>> uniform(2049);
  std::vector<uint32_t>& tables = uniform[symbols_];
  const size_t words = 2 * size_t(symbols_) + (decoderTable_ ? tableSize_ + 2 : 0);
  if (tables.size() < words) {
    totalCount_ = 0;
    updateCycle_ = symbols_;
    std::fill(symbolCount_, symbolCount_ + symbols_, 1u);
    update();
    tables.assign(storage_.get(), storage_.get() + words);
  } else {
    std::memcpy(storage_.get(), tables.data(), words * sizeof(uint32_t));
    totalCount_ = symbols_; // update()'s sum of the counts of 1
  }
  symbolsUntilUpdate_ = updateCycle_ = (symbols_ + 6) >> 1;
  ready_ = true;
}

POINTRAST_LAZ_NO_COVERAGE void SymbolModel::update() {
  if ((totalCount_ += updateCycle_) > kMaxCount) {
    totalCount_ = 0;
    for (uint32_t n = 0; n < symbols_; ++n)
      totalCount_ += (symbolCount_[n] = (symbolCount_[n] + 1) >> 1);
  }
  const uint32_t scale = 0x80000000u / totalCount_;
  uint32_t sum = 0;
  if (!decoderTable_) {
    for (uint32_t k = 0; k < symbols_; ++k) {
      distribution_[k] = (scale * sum) >> (31 - kLengthShift);
      sum += symbolCount_[k];
    }
  } else {
    // Entries s + 1 .. w of the table go to symbol k - 1. They are written four at a time, the first
    // four whether or not the symbol has any: most have four or fewer, and a loop that stops after a
    // data-dependent count mispredicted (0.9 times a decoded point of format 3). Entries written
    // beyond w are written again by the next symbols or by the fill after the loop (w < tableSize,
    // so the writes stay below tableSize + 4).
    uint32_t s = 0;
    for (uint32_t k = 0; k < symbols_; ++k) {
      distribution_[k] = (scale * sum) >> (31 - kLengthShift);
      sum += symbolCount_[k];
      const uint32_t w = distribution_[k] >> tableShift_;
      uint32_t j = s;
      do {
        uint32_t* p = decoderTable_ + j + 1;
        p[0] = p[1] = p[2] = p[3] = k - 1;
        j += 4;
      } while (j < w);
      s = w;
    }
    decoderTable_[0] = 0;
    while (s <= tableSize_)
      decoderTable_[++s] = symbols_ - 1;
  }
  updateCycle_ = std::min((5 * updateCycle_) >> 2, (symbols_ + 6) << 3);
  symbolsUntilUpdate_ = updateCycle_;
}

// ---- encoder ----------------------------------------------------------------------------------------

void ArithmeticEncoder::writeBits(uint32_t bits, uint32_t value) {
  assert(bits >= 1 && bits <= 32);
  if (bits > 19) {
    writeBits(16, value & 0xFFFF);
    value >>= 16;
    bits -= 16;
  }
  const uint32_t length = length_ >> bits;
  const uint32_t x = value * length;
  const uint32_t base = base_ + x;
  if (base < x) propagateCarry();
  normalize(base, length);
}

std::span<const uint8_t> ArithmeticEncoder::flush() {
  const uint32_t initBase = base_;
  bool anotherByte = true;
  if (length_ > 2 * kMinLength) {
    base_ += kMinLength;
    length_ = kMinLength >> 1;
  } else {
    base_ += kMinLength >> 1;
    length_ = kMinLength >> 9;
    anotherByte = false;
  }
  if (initBase > base_) propagateCarry();
  normalize(base_, length_); // length is below 2^24: at least one byte, as FastAC's final renormalization
  // Zero bytes so the decoder's reads ahead stay inside the stream.
  if (ptr_ >= limit_) grow();
  const size_t zeros = anotherByte ? 3 : 2;
  std::memset(ptr_, 0, zeros);
  ptr_ += zeros;
  const std::span<const uint8_t> bytes(buffer_.get(), ptr_);
  ptr_ = buffer_.get();
  base_ = 0;
  length_ = kMaxLength;
  return bytes;
}

std::vector<uint8_t> ArithmeticEncoder::finish() {
  const std::span<const uint8_t> bytes = flush();
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

uint8_t* ArithmeticEncoder::grow() {
  const size_t used = buffer_ ? size_t(ptr_ - buffer_.get()) : 0;
  const size_t capacity = std::max<size_t>(4096, buffer_ ? 2 * size_t(limit_ + 3 - buffer_.get()) : 0);
  auto bigger = std::make_unique<uint8_t[]>(capacity);
  if (used) std::memcpy(bigger.get(), buffer_.get(), used);
  buffer_ = std::move(bigger);
  ptr_ = buffer_.get() + used;
  limit_ = buffer_.get() + capacity - 3;
  return ptr_;
}

void ArithmeticEncoder::propagateCarry() {
  // FastAC's interval arithmetic guarantees a carry never runs past the first byte.
  for (uint8_t* p = ptr_; p != buffer_.get();) {
    --p;
    if (*p != 0xFF) {
      ++*p;
      return;
    }
    *p = 0;
  }
}

} // namespace pointrast::io::laz
