// A deterministic procedural cloud written as a .vdb file: the test and benchmark scenes' cloud
// (tools/make_cloud_vdb.py, testenv/vdb_cloud.usda) without shipping a binary asset. Fractal value
// noise (five octaves, quintic fade as in Perlin 2002, "Improving Noise") shaped by a sphere.
#pragma once

#include <cstdint>
#include <string>

namespace volphoton {

/// Writes a deterministic procedural cloud as a FloatGrid named "density" to `path`: a smooth
/// fractal value-noise blob inside a sphere of radius 0.45 * resolution voxels centred in a
/// resolution^3 box with its index-space origin at the corner, values in [0, 1], 0 (inactive) outside
/// the blob, voxel size `voxelSize` scene units. The same (resolution, voxelSize, seed) gives the
/// same voxels on every run, whatever the thread count (the file's bytes differ only in the UUID
/// OpenVDB stamps into every file). Throws std::invalid_argument on resolution < 1 or voxelSize <= 0
/// and std::runtime_error when the file cannot be written.
void writeProceduralCloudVdb(const std::string& path, int resolution, double voxelSize, uint64_t seed);

}  // namespace volphoton
