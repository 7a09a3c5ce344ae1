"""A small glTF 2.0 writer on numpy, independent of the translator under test.

Used by the glTF tests (round trips with every accessor component type, sparse accessors, several
scenes, TRS and matrix nodes, .gltf with an external .bin or a data URI, .glb) and by
tools/make_gltf_assets.py.  It writes exactly the bytes it is given: values are stored in the
requested component type, so a test knows what the file holds without reading it back with the
code under test.  Layout per the glTF 2.0 specification (GLB: 12-byte header, JSON chunk padded with
spaces, BIN chunk padded with zeros; buffer views aligned to 4 bytes).
"""

from __future__ import annotations

import base64
import json
import struct
from typing import Dict, List, Optional, Sequence

import numpy as np

BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT, UNSIGNED_INT, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
DTYPES = {BYTE: np.int8, UNSIGNED_BYTE: np.uint8, SHORT: np.int16, UNSIGNED_SHORT: np.uint16,
          UNSIGNED_INT: np.uint32, FLOAT: np.float32}
TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN, POINTS, LINES = 4, 5, 6, 0, 1


def normalized_to_float(values: np.ndarray, component_type: int) -> np.ndarray:
    """The spec's normalized-integer decoding (glTF 2.0, 3.11), in float32 like the translator."""
    c = np.asarray(values).astype(np.float32)
    if component_type == BYTE:
        return np.maximum(c / np.float32(127), np.float32(-1))
    if component_type == UNSIGNED_BYTE:
        return c / np.float32(255)
    if component_type == SHORT:
        return np.maximum(c / np.float32(32767), np.float32(-1))
    if component_type == UNSIGNED_SHORT:
        return c / np.float32(65535)
    return c


class GltfWriter:
    def __init__(self):
        self.doc: Dict = {"asset": {"version": "2.0", "generator": "hdVolPhoton tools/gltf_writer.py"},
                          "buffers": [], "bufferViews": [], "accessors": [], "meshes": [], "nodes": [],
                          "scenes": [], "materials": []}
        self.blob = bytearray()

    # ---- buffers ---------------------------------------------------------------------------------
    def buffer_view(self, data: bytes, stride: Optional[int] = None, target: Optional[int] = None) -> int:
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        if target:
            view["target"] = target
        self.blob += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, component_type: int, normalized: bool = False, stride: Optional[int] = None,
                 target: Optional[int] = None, minmax: bool = False, byte_offset: int = 0) -> int:
        """values: (count, n) or (count,) in the component type's integer/float representation.
        stride > element size interleaves padding bytes (filled with 0xAB) between elements."""
        a = np.asarray(values)
        a = a.reshape(len(a), -1)
        count, n = a.shape
        stored = a.astype(DTYPES[component_type])
        element = stored.itemsize * n
        if stride and stride > element:
            rows = bytearray(b"\xab" * byte_offset)
            for row in stored:
                rows += row.tobytes() + b"\xab" * (stride - element)
            data = bytes(rows)
        else:
            data = b"\xab" * byte_offset + stored.tobytes()
        acc = {"bufferView": self.buffer_view(data, stride, target), "componentType": component_type,
               "count": count, "type": TYPES[n]}
        if byte_offset:
            acc["byteOffset"] = byte_offset
        if normalized:
            acc["normalized"] = True
        if minmax:
            acc["min"] = [float(x) for x in stored.min(axis=0)]
            acc["max"] = [float(x) for x in stored.max(axis=0)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def sparse_accessor(self, base, count: int, n: int, component_type: int, indices, values,
                        index_type: int = UNSIGNED_SHORT, normalized: bool = False) -> int:
        """An accessor whose elements `indices` are replaced by `values`; base None: zeros (no
        bufferView), else the dense values (count, n)."""
        idx = np.asarray(indices).astype(DTYPES[index_type])
        vals = np.asarray(values).reshape(len(idx), n).astype(DTYPES[component_type])
        acc = {"componentType": component_type, "count": count, "type": TYPES[n],
               "sparse": {"count": len(idx),
                          "indices": {"bufferView": self.buffer_view(idx.tobytes()), "componentType": index_type},
                          "values": {"bufferView": self.buffer_view(vals.tobytes())}}}
        if base is not None:
            acc["bufferView"] = self.buffer_view(np.asarray(base).reshape(count, n).astype(DTYPES[component_type])
                                                 .tobytes())
        if normalized:
            acc["normalized"] = True
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    # ---- scene graph -----------------------------------------------------------------------------
    def material(self, base_color=(1, 1, 1, 1), metallic=0.0, roughness=1.0, emissive=None, name=None,
                 alpha_mode=None, alpha_cutoff=None) -> int:
        m = {"pbrMetallicRoughness": {"baseColorFactor": list(base_color), "metallicFactor": metallic,
                                      "roughnessFactor": roughness}}
        if emissive is not None:
            m["emissiveFactor"] = list(emissive)
        if name:
            m["name"] = name
        if alpha_mode:
            m["alphaMode"] = alpha_mode
        if alpha_cutoff is not None:
            m["alphaCutoff"] = alpha_cutoff
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, primitives: Sequence[Dict], name: Optional[str] = None) -> int:
        """primitives: dicts with "attributes" {name: accessor}, optional "indices", "material", "mode"."""
        m = {"primitives": list(primitives)}
        if name:
            m["name"] = name
        self.doc["meshes"].append(m)
        return len(self.doc["meshes"]) - 1

    def node(self, name=None, mesh=None, children=(), translation=None, rotation=None, scale=None,
             matrix=None) -> int:
        n: Dict = {}
        for key, value in (("name", name), ("mesh", mesh), ("translation", translation),
                           ("rotation", rotation), ("scale", scale), ("matrix", matrix)):
            if value is not None:
                n[key] = list(value) if isinstance(value, (list, tuple, np.ndarray)) else value
        if children:
            n["children"] = list(children)
        self.doc["nodes"].append(n)
        return len(self.doc["nodes"]) - 1

    def scene(self, nodes: List[int], name: Optional[str] = None, default: bool = False) -> int:
        s: Dict = {"nodes": list(nodes)}
        if name:
            s["name"] = name
        self.doc["scenes"].append(s)
        if default:
            self.doc["scene"] = len(self.doc["scenes"]) - 1
        return len(self.doc["scenes"]) - 1

    # ---- files -----------------------------------------------------------------------------------
    def _json(self, buffer: Dict) -> Dict:
        doc = {k: v for k, v in self.doc.items() if v != []}
        doc["buffers"] = [buffer]
        return doc

    def write_gltf(self, path: str, bin_name: Optional[str] = None) -> None:
        """.gltf with the buffer in `bin_name` next to it, or embedded as a data URI when None."""
        import os
        if bin_name is None:
            uri = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.blob)).decode()
        else:
            uri = bin_name
            with open(os.path.join(os.path.dirname(os.path.abspath(path)), bin_name), "wb") as f:
                f.write(self.blob)
        with open(path, "w") as f:
            json.dump(self._json({"byteLength": len(self.blob), "uri": uri}), f)

    def glb_bytes(self) -> bytes:
        text = json.dumps(self._json({"byteLength": len(self.blob)})).encode()
        text += b" " * (-len(text) % 4)
        blob = bytes(self.blob) + b"\0" * (-len(self.blob) % 4)
        total = 12 + 8 + len(text) + 8 + len(blob)
        return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(text), b"JSON") + text
                + struct.pack("<I4s", len(blob), b"BIN\0") + blob)

    def write_glb(self, path: str) -> None:
        with open(path, "wb") as f:
            f.write(self.glb_bytes())
