// Deterministic random numbers. Every stream is seeded from a hash of what identifies the sample
// (pixel, sample index, pass, user seed), never from a clock, so a render is bit-identical across runs.
#pragma once

#include <cstdint>
#include <cstring>

namespace volphoton {

/// 64-bit finaliser of MurmurHash3 (Appleby); mixes all input bits into all output bits.
inline uint64_t mix64(uint64_t v) {
    v ^= v >> 33;
    v *= 0xff51afd7ed558ccdULL;
    v ^= v >> 33;
    v *= 0xc4ceb9fe1a85ec53ULL;
    v ^= v >> 33;
    return v;
}

/// Hash of any number of integer keys.
template <typename... Ts>
uint64_t hashKeys(Ts... keys) {
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    ((h = mix64(h ^ (static_cast<uint64_t>(keys) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2)))), ...);
    return h;
}

/// PCG32 (O'Neill 2014, pcg-random.org): 64-bit state, 32-bit output, selectable stream.
class Rng {
public:
    Rng() { seed(0, 0); }
    explicit Rng(uint64_t seqIndex, uint64_t offset = 0) { seed(seqIndex, offset); }
    void seed(uint64_t seqIndex, uint64_t offset) {
        state_ = 0u;
        inc_ = (mix64(seqIndex) << 1u) | 1u;
        nextU32();
        state_ += mix64(offset ^ 0x853c49e6748fea9bULL);
        nextU32();
    }
    uint32_t nextU32() {
        uint64_t old = state_;
        state_ = old * 0x5851f42d4c957f2dULL + inc_;
        uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }
    /// Uniform in [0, 1): 53 random bits from two draws, so the value is never rounded up to 1.
    double uniform() {
        uint64_t hi = nextU32() >> 5, lo = nextU32() >> 6;  // 27 + 26 bits
        return static_cast<double>((hi << 26) | lo) * (1.0 / 9007199254740992.0);
    }

private:
    uint64_t state_, inc_;
};

}  // namespace volphoton
