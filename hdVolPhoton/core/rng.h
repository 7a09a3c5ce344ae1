// Deterministic random numbers. Every stream is seeded from a hash of what identifies the sample
// (pixel, sample index, pass, user seed), never from a clock, so a render is bit-identical across runs.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <utility>

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

/// Bits of x in reverse order.
inline uint32_t reverseBits32(uint32_t x) {
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

/// The Laine-Karras permutation with the constants of Burley 2020 ("Practical Hash-based Owen
/// Scrambling", JCGT 9(4)): applied to a bit-reversed value it is an Owen (nested uniform) scramble,
/// a bijection that maps every base-2 elementary interval onto one, so a (0, m, 2)-net stays a net.
inline uint32_t laineKarras(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}
/// Owen scrambling of a 32-bit fixed-point value.
inline uint32_t owenScramble(uint32_t x, uint32_t seed) { return reverseBits32(laineKarras(reverseBits32(x), seed)); }

/// The first two dimensions of the Sobol' sequence as 32-bit fixed point: van der Corput and the
/// second Sobol' generator matrix (v_1 = 2^31, v_{k+1} = v_k ^ (v_k >> 1)). Together a (0, 2)-sequence:
/// every power-of-two prefix stratifies the unit square into every elementary interval.
inline uint32_t sobol0(uint32_t i) { return reverseBits32(i); }
namespace detail {
/// Byte tables of the second matrix. plain: t[k][b] = XOR of the columns of the set bits of b << 8k.
/// reversed: indexed by the bit-reversed index, giving the bit-reversed value (what Owen scrambling
/// works on), so the sampler below needs no reversal for that dimension.
struct Sobol1Tables {
    uint32_t plain[4][256], reversed[4][256];
    static constexpr uint32_t rev(uint32_t x) {
        uint32_t r = 0;
        for (int j = 0; j < 32; ++j) r |= ((x >> j) & 1u) << (31 - j);
        return r;
    }
    constexpr Sobol1Tables() : plain(), reversed() {
        uint32_t col[32] = {};
        uint32_t v = 1u << 31;
        for (int j = 0; j < 32; ++j, v ^= v >> 1) col[j] = v;
        for (int k = 0; k < 4; ++k)
            for (int b = 0; b < 256; ++b) {
                uint32_t p = 0, r = 0;
                for (int j = 0; j < 8; ++j)
                    if (b & (1 << j)) {
                        p ^= col[8 * k + j];
                        r ^= rev(col[31 - (8 * k + j)]);  // bit 8k+j of the reversed index is bit 31-(8k+j) of the index
                    }
                plain[k][b] = p;
                reversed[k][b] = r;
            }
    }
};
inline constexpr Sobol1Tables kSobol1{};
inline uint32_t lookup(const uint32_t (&t)[4][256], uint32_t i) {
    return t[0][i & 0xff] ^ t[1][(i >> 8) & 0xff] ^ t[2][(i >> 16) & 0xff] ^ t[3][i >> 24];
}
}  // namespace detail
inline uint32_t sobol1(uint32_t i) { return detail::lookup(detail::kSobol1.plain, i); }
/// reverseBits32(sobol1(reverseBits32(r))), without the reversals.
inline uint32_t sobol1Reversed(uint32_t r) { return detail::lookup(detail::kSobol1.reversed, r); }

/// PCG32 (O'Neill 2014, pcg-random.org): 64-bit state, 32-bit output, selectable stream.
/// With stratify(), the first draws of a camera sample come from a randomised quasi-Monte Carlo
/// sequence instead (see there); after them, and in every other stream, PCG32.
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
        if (qmcDim_ < qmcEnd_) return stratified();
        uint64_t hi = nextU32() >> 5, lo = nextU32() >> 6;  // 27 + 26 bits
        return static_cast<double>((hi << 26) | lo) * (1.0 / 9007199254740992.0);
    }

    /// Two draws for one 2D sample. In the stratified prefix both come from one Sobol' pair (a draw
    /// is skipped when the current pair is half used), so the 2D sample is stratified as a whole.
    std::pair<double, double> uniform2() {
        if (qmcDim_ < qmcEnd_ && (qmcDim_ & 1)) ++qmcDim_;
        if (qmcDim_ + 1 >= qmcEnd_) qmcEnd_ = qmcDim_;  // no whole pair left in this event: both from PCG32
        double a = uniform();
        double b = uniform();
        return {a, b};
    }

    /// Makes dimensions [0, dims) of this sample come from sample `sampleIndex` of a padded, shuffled,
    /// Owen-scrambled 2D Sobol' sequence (Burley 2020, sec. 4; pbrt-v4's PaddedSobolSampler is the same
    /// design); draws take them in order unless startSegment()/event() place them. Dimensions
    /// 2k and 2k+1 are a (0, 2)-sequence over the sample index, its index shuffled and its values
    /// scrambled by hashes of (key, k). Each sample is still uniform on the unit hypercube (so every
    /// estimate stays unbiased and seeds stay independent), but the samples of one pixel over its
    /// passes stratify each pair of dimensions: the first bounce's pixel position, light and BSDF
    /// choices converge at up to O(1/N) instead of O(1/sqrt N). Samples of one pixel are therefore
    /// not independent: estimate errors from several seeds, not from the spread of one render's passes.
    void stratify(uint32_t sampleIndex, uint64_t key, int dims) {
        qmcIndexReversed_ = reverseBits32(sampleIndex);
        qmcKey_ = key;
        qmcDim_ = 0;
        qmcDims_ = qmcEnd_ = dims;
        qmcPairCached_ = -1;
        segmentBase_ = -1;
    }

    /// Fixed dimensions per path segment (pbrt-v4's samplers give each bounce the same dimensions;
    /// its volumetric path tracer draws delta tracking from a separate generator for that reason).
    /// Without this the k-th draw of a path belongs to whatever event happens to make it: a null
    /// collision earlier in the path shifts every later light and phase sample onto other dimensions,
    /// and the Sobol' pairs stratify nothing past the first medium. After startSegment(s), event(e)
    /// makes the next draws (at most the event's width) come from dimensions CameraDims +
    /// SegmentDims * s + offset(e); further draws of the event (ratio tracking's, delta tracking's
    /// null collisions) come from PCG32. Dimensions only move forward: an event whose dimensions a
    /// sample has already passed draws from PCG32, so no dimension is ever used twice in one sample
    /// (which would correlate two decisions of one path and bias it). Without startSegment() event()
    /// does nothing and draws take the dimensions in order (the photon map's camera paths).
    static constexpr int CameraDims = 4;    ///< pixel position pair and lens pair
    static constexpr int SegmentDims = 36;  ///< per segment: the layout of Event
    /// Each event's first dimension in its segment, in the order a segment uses them; its width runs
    /// to the next one's first (eventWidth).
    enum class Event : int {
        Equiangular = 0,    ///< 2: light pick, distance
        SegmentLight = 2,   ///< 4: distance, light pick and position pair
        Emission = 6,       ///< 8: the emission estimate's first tentative collisions and roulette
        Flight = 14,        ///< 10: the first five tentative collisions, each with its real/null choice
        Light = 24,         ///< 8: light pick and position pair, or one pair per light (lightPair)
        Scatter = 32,       ///< 3: direction pair, then lobe or Fresnel choice
        Roulette = 35,      ///< 1
    };
    static constexpr int eventWidth(Event e) {
        switch (e) {
            case Event::Equiangular: return int(Event::SegmentLight) - int(e);
            case Event::SegmentLight: return int(Event::Emission) - int(e);
            case Event::Emission: return int(Event::Flight) - int(e);
            case Event::Flight: return int(Event::Light) - int(e);
            case Event::Light: return int(Event::Scatter) - int(e);
            case Event::Scatter: return int(Event::Roulette) - int(e);
            case Event::Roulette: return SegmentDims - int(e);
        }
        return 0;
    }
    /// One of n choices for a whole path (a camera path's or photon's hero channel), drawn outside every
    /// dimension the draws above use. Under stratify() it is an Owen-scrambled van der Corput point
    /// of the sample index (its own scramble), so a pixel's passes take the n choices in near-equal
    /// numbers; otherwise a hash of PCG32's state, which it leaves as it was.
    int pathChoice(int n) {
        uint32_t v;
        if (qmcDims_ > 0) {
            uint64_t h = mix64(qmcKey_ ^ 0x68e7a1c35b2f9d01ULL);
            v = owenScramble(sobol0(reverseBits32(qmcIndexReversed_)), static_cast<uint32_t>(h));
        } else {
            // A hash of the state, which is not advanced: the stream's draws stay as they were.
            v = static_cast<uint32_t>(mix64(state_ ^ inc_ ^ 0x68e7a1c35b2f9d01ULL) >> 32);
        }
        return std::min(n - 1, static_cast<int>((static_cast<uint64_t>(v) * static_cast<uint64_t>(n)) >> 32));
    }

    void startSegment(int segment) {
        if (qmcDims_ <= 0) return;
        segmentBase_ = CameraDims + SegmentDims * segment;
        qmcEnd_ = std::min(qmcEnd_, qmcDim_);  // draws outside an event: PCG32
    }
    void event(Event e) { beginDims(static_cast<int>(e), eventWidth(e)); }
    /// The pair of light `i` of a vertex that samples every light: dimensions Light + 2i while they
    /// fit in the light event's width (four lights, Integrator's AllLightsMax), else PCG32.
    void lightPair(int i) {
        if (2 * i + 2 <= eventWidth(Event::Light)) beginDims(static_cast<int>(Event::Light) + 2 * i, 2);
        else if (segmentBase_ >= 0) qmcEnd_ = qmcDim_;
    }

private:
    void beginDims(int offset, int count) {
        if (segmentBase_ < 0) return;
        int first = segmentBase_ + offset;
        if (first >= qmcDim_ && first < qmcDims_) {
            qmcDim_ = first;
            qmcEnd_ = std::min(first + count, qmcDims_);
        } else {
            qmcEnd_ = qmcDim_;  // passed (or beyond the stratified dimensions): PCG32
        }
    }

    double stratified() {
        int pair = qmcDim_ >> 1;
        if (pair != qmcPairCached_) {
            qmcPairCached_ = pair;
            // Shuffled index i = owenScramble(index) = reverse(r); values owenScramble(sobol0(i)) and
            // owenScramble(sobol1(i)), with the bit reversals that cancel left out.
            uint64_t h = mix64(qmcKey_ + static_cast<uint64_t>(pair + 1) * 0x9e3779b97f4a7c15ULL);
            uint32_t r = laineKarras(qmcIndexReversed_, static_cast<uint32_t>(h));
            qmcPair_[0] = reverseBits32(laineKarras(reverseBits32(r), static_cast<uint32_t>(h >> 32)));
            qmcPair_[1] = reverseBits32(laineKarras(sobol1Reversed(r), static_cast<uint32_t>(mix64(h))));
        }
        uint32_t v = qmcPair_[qmcDim_++ & 1];
        return v * (1.0 / 4294967296.0);
    }

    uint64_t state_, inc_;
    uint64_t qmcKey_ = 0;
    uint32_t qmcIndexReversed_ = 0, qmcPair_[2] = {0, 0};
    int qmcDim_ = 0, qmcDims_ = 0, qmcEnd_ = 0, qmcPairCached_ = -1;
    int segmentBase_ = -1;  ///< first dimension of the current segment; -1: draws in order
};

}  // namespace volphoton
