// Photon beams (Jarosz, Nowrouzezahrai, Sadeghi and Jensen 2011, "A comprehensive theory of volumetric
// radiance estimation using photon points and beams"; Jarosz, Nowrouzezahrai, Thomas, Sloan and
// Zwicker 2011, "Progressive photon beams"): the photon map's multiple scattering from the photons'
// flight segments instead of their collision points.
//
// Estimator: "beam x beam 1D" with short beams. A beam is a stretch of a photon's free flight through
// a medium (from an event, a boundary or a null collision that changes its spectral weight, to the
// next), carrying the flux that travels it. A camera segment gathers every beam that passes within r
// of it: at the two lines' closest points (camera t, beam s), with theta the angle between them,
//     L += flux sigma_s(x_s) p(cos) / (2 r sin(theta)) T_camera(t),
// the 1D box kernel 1/(2r) across both lines (PPB eq. 4, beam-beam with the blur along the common
// perpendicular). Short beams end where the flight ended, so the probability that a beam covers a
// point stands for the beam's transmittance (PPB sec. 4.2); in chromatic media the spectral MIS
// weights of null collisions under the channels' largest majorant (photonMapper.cpp: flights that
// leave beams keep that majorant) make that unbiased per channel (each weight change starts a new
// beam).
// The radius shrinks as r_{i+1} = r_i (i + alpha)/(i + 1) (PPB eq. 21: a 1D kernel, not r^2).
//
// Thin media are where beams pay: a point photon informs only camera rays passing within r of its
// collision, a beam every camera ray within r of its whole flight (the fog of benchmark scene 4).
#pragma once

#include <vector>

#include "core/embreeRay.h"
#include "core/functionRef.h"
#include "core/math.h"

namespace volphoton {

/// One stretch of a photon's flight in a medium, multiply scattered light only (see PhotonMapper).
struct PhotonBeam {
    float origin[3];
    float dir[3];  ///< unit propagation direction
    float length;
    float power[3];  ///< flux along the beam (before any event at its end)
    int region : 31;  ///< innermost medium mesh (-1: outside every mesh), as Photon::region
    unsigned half : 1;  ///< as Photon::half
    /// Kernel radius of this beam: the tracer stores a cap tied to the mean free path where the piece
    /// ended (as Photon::radius); the map lowers it to the pass radius.
    float radius;
};

/// What a query found: the beam and the closest points of the two lines.
struct BeamHit {
    const PhotonBeam* beam;
    double tCamera;    ///< along the query ray
    double sBeam;      ///< along the beam, from its origin
    double sinTheta;   ///< sine of the angle between the two directions
    double cosTheta;   ///< beam direction . (-query direction): the scattering angle's cosine
};

/// \class PhotonBeamMap
/// A pass's beams in an Embree BVH of user geometry (each beam's box grown by the radius); queries
/// run concurrently. Beams (almost) parallel to the query ray (sin theta < 1e-4) are skipped: the
/// kernel's 1/sin(theta) is integrable, and such beams are a vanishing share.
class PhotonBeamMap {
public:
    PhotonBeamMap(std::vector<PhotonBeam> beams, double radius);

    /// Calls visit for every beam whose closest approach to the segment ray.o + t ray.d, t in
    /// [tMin, tMax], lies within its radius (PhotonBeam::radius, at most radius()), on the beam, and
    /// at such a t.
    void query(const Ray& ray, double tMin, double tMax, FunctionRef<void(const BeamHit&)> visit) const;
    /// The pass radius: the largest beam radius.
    double radius() const { return radius_; }
    size_t size() const { return beams_.size(); }
    size_t bytes() const { return beams_.size() * BytesPerBeam; }
    /// The record, its box in Embree's BVH (an estimate of 48 bytes with the node share).
    static constexpr size_t BytesPerBeam = sizeof(PhotonBeam) + 48;

private:
    std::vector<PhotonBeam> beams_;
    double radius_;
    EmbreeScene embree_{"the photon beams"};
};

}  // namespace volphoton
