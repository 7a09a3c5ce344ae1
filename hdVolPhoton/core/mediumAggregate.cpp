#include "core/mediumAggregate.h"

#include "core/workCount.h"

#include <vector>

namespace volphoton {

bool MediumAggregate::add(const Medium* medium) {
    if (!medium || count_ == MaxMedia) return false;
    media_[count_++] = medium;
    lookupCost_ += medium->lookupCost();
    closedForm_ &= medium->hasClosedFormDepth();
    return true;
}

MediumProperties MediumAggregate::properties(const Vec3& p) const {
    work::lookups += lookupCost_;
    if (count_ == 1) return media_[0]->properties(p);  // the sum below, without building it twice
    MediumProperties sum;
    for (int i = 0; i < count_; ++i) {
        MediumProperties mp = media_[i]->properties(p);
        sum.sigma_a += mp.sigma_a;
        sum.emission += mp.emission;
        for (int l = 0; l < mp.lobeCount; ++l) sum.addLobe(mp.lobes[l].phase, mp.lobes[l].sigma_s);
    }
    return sum;
}

Spectrum MediumAggregate::extinction(const Vec3& p) const {
    work::lookups += lookupCost_;
    Spectrum sum;
    for (int i = 0; i < count_; ++i) sum += media_[i]->extinction(p);
    return sum;
}

namespace {
/// Upper bound of a segment's majorant over [a, b] (inside the segment).
double boundOver(const MajorantSegment& s, double a, double b) {
    if (s.decay == 0) return s.sigmaMaj;
    double from = s.decay > 0 ? a : b;  // the majorant is largest at the end it decays from
    return s.sigmaMaj * std::exp(std::min(-s.decay * (from - s.tMin), 700.0));
}
}  // namespace

// Majorants of overlapping media add. Where a single medium covers an interval its segment passes
// through unchanged (an exponential atmosphere keeps its exact decaying majorant); where several
// overlap, the sum is bounded by constants on pieces short enough that a decaying term varies by at
// most a factor of two (capped at 64 pieces per interval, which only loosens the bound).
void MediumAggregate::majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const {
    if (count_ == 0) return;
    if (count_ == 1) return media_[0]->majorants(ray, tMin, tMax, segment);

    thread_local std::vector<MajorantSegment> segs[MaxMedia];
    thread_local std::vector<double> cuts;
    cuts.clear();
    for (int i = 0; i < count_; ++i) {
        segs[i].clear();
        media_[i]->majorants(ray, tMin, tMax, [&](const MajorantSegment& s) {
            segs[i].push_back(s);
            cuts.push_back(s.tMin);
            cuts.push_back(s.tMax);
            return true;
        });
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());

    size_t cursor[MaxMedia] = {};
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
        double a = cuts[c], b = cuts[c + 1];
        const MajorantSegment* covering[MaxMedia];
        int n = 0;
        double maxDecay = 0;
        for (int i = 0; i < count_; ++i) {
            while (cursor[i] < segs[i].size() && segs[i][cursor[i]].tMax <= a) ++cursor[i];
            if (cursor[i] < segs[i].size() && segs[i][cursor[i]].tMin <= a) {
                covering[n++] = &segs[i][cursor[i]];
                maxDecay = std::max(maxDecay, std::abs(segs[i][cursor[i]].decay));
            }
        }
        if (n == 0) continue;
        if (n == 1) {
            const MajorantSegment& s = *covering[0];
            double start = s.decay == 0 ? s.sigmaMaj : s.sigmaMaj * std::exp(std::min(-s.decay * (a - s.tMin), 700.0));
            if (!segment(MajorantSegment{a, b, start, s.decay, s.channelScale})) return;
            continue;
        }
        int pieces = 1;
        if (maxDecay > 0) pieces = static_cast<int>(std::clamp(std::ceil((b - a) * maxDecay / std::log(2.0)), 1.0, 64.0));
        for (int k = 0; k < pieces; ++k) {
            double pa = a + (b - a) * k / pieces, pb = k + 1 == pieces ? b : a + (b - a) * (k + 1) / pieces;
            double sum = 0;
            for (int j = 0; j < n; ++j) sum += boundOver(*covering[j], pa, pb);
            if (!segment(MajorantSegment{pa, pb, sum, 0.0})) return;
        }
    }
}

std::optional<Spectrum> MediumAggregate::opticalDepth(const Ray& ray, double t0, double t1) const {
    Spectrum tau;
    for (int i = 0; i < count_; ++i) {
        std::optional<Spectrum> part = media_[i]->opticalDepth(ray, t0, t1);
        if (!part) return std::nullopt;
        tau += *part;
    }
    return tau;
}

Bounds3 MediumAggregate::bounds() const {
    Bounds3 b;
    for (int i = 0; i < count_; ++i) b.extend(media_[i]->bounds());
    return b;
}

bool MediumAggregate::isEmissive() const {
    for (int i = 0; i < count_; ++i)
        if (media_[i]->isEmissive()) return true;
    return false;
}

double MediumAggregate::maxAlbedo() const {
    double m = 0;
    for (int i = 0; i < count_; ++i) m = std::max(m, media_[i]->maxAlbedo());
    return m;
}

double MediumAggregate::phasePeak() const {
    double m = 1;
    for (int i = 0; i < count_; ++i) m = std::max(m, media_[i]->phasePeak());
    return m;
}

std::string MediumAggregate::describe() const {
    std::string s = "aggregate(";
    for (int i = 0; i < count_; ++i) s += (i ? ", " : "") + media_[i]->describe();
    return s + ")";
}

}  // namespace volphoton
