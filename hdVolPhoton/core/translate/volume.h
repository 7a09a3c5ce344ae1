// A UsdVol Volume whose density comes from OpenVDB fields, translated once for every front end:
// which grid of which file each field: slot names, and loading it with the reader guard.
//
// A front end reads the OpenVDBAsset prims bound to the volume's field:<slot> relationships
// (usd-core: volphoton.usdscene; Hydra: the delegate's field Bprims) into GridFieldInput records and
// calls gridMediumFromFields, then loadGridMediumReported. The rules live here only:
//
// | rule                 | behaviour                                                                  |
// |----------------------|----------------------------------------------------------------------------|
// | slots                | density (required), temperature, emission, albedo                          |
// | grid name            | the asset's fieldName; the slot's name when fieldName is not authored      |
// | one file per volume  | a field in another file than the density's: error on that field, ignored   |
// | fieldIndex           | not used (the first grid of the name is taken): a warning when above 0     |
// | reader guard         | vdbCrashCheck before loading: a crashing file is an error, volume skipped  |
// | load errors          | reported on the density asset (fieldName for a missing grid, else filePath)|
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/gridMedium.h"
#include "core/translate/medium.h"
#include "core/translate/record.h"

namespace volphoton::translate {

/// One OpenVDBAsset bound to a volume's field:<slot> relationship, as a front end read it.
///
/// | field      | type   | default | meaning                                                          |
/// |------------|--------|---------|------------------------------------------------------------------|
/// | slot       | string |         | the relationship's name after "field:" (density, emission, ...) |
/// | primPath   | string |         | the OpenVDBAsset prim, for messages                              |
/// | filePath   | string | ""      | resolved file; "" when it could not be resolved (reported there) |
/// | fieldName  | string | ""      | the grid's name; "" when not authored                            |
/// | fieldIndex | int    | -1      | -1 when not authored (the delegate sees 0 then)                  |
struct GridFieldInput {
    std::string slot;
    std::string primPath;
    std::string filePath;
    std::string fieldName;
    int fieldIndex = -1;
};

/// The GridMediumDesc of the volume at volumePath: every medium parameter (gridMediumDesc), the file
/// and grid names from its fields (the table above) and the voxel cap. nullopt when there is no
/// density field with a resolved file: whoever read the field reported why, so nothing is added.
/// Fields with slots other than the four are ignored.
std::optional<GridMediumDesc> gridMediumFromFields(const std::string& volumePath, const MediumParams& params,
                                                   const Affine& objectToWorld,
                                                   const std::vector<GridFieldInput>& fields,
                                                   std::uint64_t maxActiveVoxels, Diagnostics& diagnostics);

/// loadGridMedium(desc) behind the reader guard (vdbCrashCheck); nullptr with an error on the density
/// asset densityPrim (naming the volume, the file and the grid) when the file would crash the reader
/// or cannot be loaded.
MediumPtr loadGridMediumReported(const std::string& volumePath, const std::string& densityPrim,
                                 const GridMediumDesc& desc, Diagnostics& diagnostics);

}  // namespace volphoton::translate
