// A deterministic procedural cloud written as a .vdb file: the test and benchmark scenes' cloud
// (tools/make_cloud_vdb.py, testenv/vdb_cloud.usda) without shipping a binary asset. Two shapes:
//  - Blob: fractal value noise (five octaves, quintic fade as in Perlin 2002, "Improving Noise")
//    shaped by a sphere. The tests and the benchmark use it (their figures refer to it).
//  - Cumulus: the example scenes' cloud: a flat-based heap of overlapping puffs whose surface is
//    carved by billows of inverted Worley (cellular) noise at three octaves (Worley 1996, "A Cellular
//    Texture Basis Function") and eroded by value-noise fBm, the recipe of Schneider and Vos 2015
//    ("The real-time volumetric cloudscapes of Horizon: Zero Dawn", SIGGRAPH course): sharp sunlit
//    billows and wispy edges, so single and multiple scattering both show.
#pragma once

#include <cstdint>
#include <string>

namespace volphoton {

/// Writes a deterministic procedural cloud as a FloatGrid named "density" to `path`: (Blob) a smooth
/// fractal value-noise blob inside a sphere of radius 0.45 * resolution voxels, or (Cumulus) the
/// billowed heap above inside the same sphere, centred in a resolution^3 box with its index-space origin at the corner, values in [0, 1], 0 (inactive) outside
/// the blob, voxel size `voxelSize` scene units. The same (resolution, voxelSize, seed) gives the
/// same voxels on every run, whatever the thread count (the file's bytes differ only in the UUID
/// OpenVDB stamps into every file). Throws std::invalid_argument on resolution < 1 or voxelSize <= 0
/// and std::runtime_error when the file cannot be written.
enum class CloudShape { Blob, Cumulus };
void writeProceduralCloudVdb(const std::string& path, int resolution, double voxelSize, uint64_t seed,
                             CloudShape shape = CloudShape::Blob);

}  // namespace volphoton
