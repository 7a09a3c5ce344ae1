#include "core/photonCache.h"

#include "core/photonBeams.h"
#include "core/photonMap.h"

namespace volphoton {

size_t PhotonCache::Pass::size() const { return (map ? map->size() : 0) + (beams ? beams->size() : 0); }

size_t PhotonCache::Pass::bytes() const { return (map ? map->bytes() : 0) + (beams ? beams->bytes() : 0); }

bool PhotonCache::use(uint64_t key) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (hasKey_ && key == key_) return true;
    passes_.clear();
    bytes_ = 0;
    photonsPerPass_ = 0;
    resizedPhotonsPerPass_ = 0;
    measuredChoice_ = Choice::Unmeasured;
    key_ = key;
    hasKey_ = true;
    return false;
}

std::shared_ptr<const PhotonCache::Pass> PhotonCache::find(int pass) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = passes_.find(pass);
    return it == passes_.end() ? nullptr : it->second;
}

bool PhotonCache::store(int pass, Pass entry, size_t budgetBytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    if ((!entry.map && !entry.beams) || passes_.count(pass)) return false;
    size_t b = entry.bytes();
    if (bytes_ + b > budgetBytes) return false;
    bytes_ += b;
    passes_[pass] = std::make_shared<const Pass>(std::move(entry));
    return true;
}

int PhotonCache::photonsPerPass() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return photonsPerPass_;
}

void PhotonCache::setPhotonsPerPass(int n) {
    std::lock_guard<std::mutex> lock(mutex_);
    photonsPerPass_ = n;
}

int PhotonCache::resizedPhotonsPerPass() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return resizedPhotonsPerPass_;
}

void PhotonCache::setResizedPhotonsPerPass(int n) {
    std::lock_guard<std::mutex> lock(mutex_);
    resizedPhotonsPerPass_ = n;
}

PhotonCache::Choice PhotonCache::measuredChoice() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return measuredChoice_;
}

void PhotonCache::setMeasuredChoice(Choice c) {
    std::lock_guard<std::mutex> lock(mutex_);
    measuredChoice_ = c;
}

size_t PhotonCache::passes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return passes_.size();
}

size_t PhotonCache::bytes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return bytes_;
}

void PhotonCache::clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    passes_.clear();
    bytes_ = 0;
    photonsPerPass_ = 0;
    resizedPhotonsPerPass_ = 0;
    measuredChoice_ = Choice::Unmeasured;
    hasKey_ = false;
}

}  // namespace volphoton
