"""Blender Cycles (CPU, the `bpy` module from PyPI) peer of the benchmark: builds a Blender scene
from the shared description (scenes.py) and renders it at a series of sample counts.

    python tools/bench/peer_cycles.py render    --scene NAME --size W H --budgets 0.5,1,2 --out f.npz
    python tools/bench/peer_cycles.py reference --scene NAME --size W H --seconds 30 --batches 8 --out f.npz
    python tools/bench/peer_cycles.py check                      # is bpy importable? (JSON on stdout)

Mapping from the description (Y-up USD -> Blender's Z-up: (x, y, z) -> (x, -z, y), a rotation):
    * camera: perspective, sensor_fit HORIZONTAL, angle = fov_x, clip range as described;
    * lambertian meshes -> Diffuse BSDF (roughness 0 = Lambert); media -> meshes whose material has
      only a Volume output (an invisible boundary) with a Volume Coefficients node: scatter =
      albedo * sigma_t, absorption = (1 - albedo) * sigma_t, emission, phase HG / Rayleigh / isotropic
      (HG g = 0); the VDB cloud is a Volume object reading the same .vdb file, precision FULL,
      clipping 0, density in WORLD space; the exponential atmosphere evaluates a exp(-b z) from the
      shading position in the node tree;
    * lights: world background = dome radiance; sun (strength = irradiance, angle 0); spot with
      radius 0, blend 0, power = 4 pi I (Cycles' point/spot intensity is P / (4 pi) W/sr);
    * bounces: every kind = maxDepth - 1 (Cycles' 0 bounces = direct light only), capped at 1024;
      transparent bounces 1024 (medium boundaries).
Defaults that would change the answer are overridden: sample_clamp_direct/indirect 0, light sampling
threshold 0, blur_glossy 0, adaptive sampling off, denoising off, pixel filter BOX of width 1 px, light
tree off, volume_biased off, view transform Standard (look None, exposure 0, gamma 1), film exposure
1; the output is a 32-bit float EXR of linear radiance.
Timing: each budget is one render at a power-of-two sample count with its own seed; the time is the
sampling time (render_stats from 'Sample 0/N' to 'Finished'); the per-render set-up before the
first sample (scene sync, BVH, volume preprocessing: density evaluation and the majorant octree)
is reported separately, the volume part from the 'Updating Volume' status messages.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(REPO, "tools", "out", "bench")
sys.path.insert(0, HERE)

import scenes as S  # noqa: E402

# USD (Y up) -> Blender (Z up)
C = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])
MAX_BOUNCES = 1024


def unsupported(scene: S.BenchScene):
    if "TranslucentMesh" in scene.features():
        # Issue #7 names Mitsuba 3 as the subsurface peer; a Cycles mapping (glass BSDF + volume
        # scatter/absorption with matching Fresnel) is not written.
        return ["translucent (dielectric + medium) meshes are not mapped to Cycles"]
    return []


def _mat(m):
    from mathutils import Matrix

    return Matrix([list(map(float, row)) for row in m])


def _reset():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy


def configure(bpy, scene: S.BenchScene, width: int, height: int, spp: int, seed: int, threads: int):
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = int(spp)
    cy.seed = int(seed)
    cy.use_animated_seed = False
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.use_preview_denoising = False
    n = max(0, min(MAX_BOUNCES, scene.max_depth - 1))
    cy.max_bounces = n
    cy.diffuse_bounces = n
    cy.glossy_bounces = n
    cy.transmission_bounces = n
    cy.volume_bounces = n
    cy.transparent_max_bounces = MAX_BOUNCES
    cy.min_light_bounces = 0
    cy.min_transparent_bounces = 0
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.use_light_tree = False
    cy.blur_glossy = 0.0
    cy.caustics_reflective = True
    cy.caustics_refractive = True
    cy.volume_biased = False
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.film_exposure = 1.0
    sc.render.film_transparent = False
    cy.use_auto_tile = False
    sc.render.use_persistent_data = False
    sc.render.threads_mode = "FIXED"
    sc.render.threads = int(threads)
    sc.render.resolution_x = int(width)
    sc.render.resolution_y = int(height)
    sc.render.resolution_percentage = 100
    sc.render.pixel_aspect_x = sc.render.pixel_aspect_y = 1.0
    sc.render.use_border = False
    sc.view_settings.view_transform = "Standard"
    sc.view_settings.look = "None"
    sc.view_settings.exposure = 0.0
    sc.view_settings.gamma = 1.0
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    sc.render.image_settings.exr_codec = "NONE"
    sc.render.image_settings.color_mode = "RGBA"
    return sc


def _diffuse_material(bpy, name, albedo):
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*albedo, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    return mat


def _volume_material(bpy, name, albedo, phase: S.Phase, density_socket_builder, sigma_rgb=(1.0, 1.0, 1.0),
                     emission=None):
    """Volume-only material: coefficients = density(x) * sigma_rgb * (albedo | 1 - albedo), emission =
    density_raw(x) * emission. density_socket_builder(nt) -> (sigma scale socket, raw density socket)."""
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    vc = nt.nodes.new("ShaderNodeVolumeCoefficients")
    vc.phase = {"hg": "HENYEY_GREENSTEIN", "isotropic": "HENYEY_GREENSTEIN", "rayleigh": "RAYLEIGH"}[phase.kind]
    if phase.kind != "rayleigh":  # isotropic = HG with g = 0 (Rayleigh has no parameter socket)
        vc.inputs["Anisotropy"].default_value = float(phase.g) if phase.kind == "hg" else 0.0
    sigma, raw = density_socket_builder(nt)

    def scaled(vec, socket):
        vm = nt.nodes.new("ShaderNodeVectorMath")
        vm.operation = "SCALE"
        vm.inputs[0].default_value = [float(v) for v in vec]
        if socket is None:
            vm.inputs["Scale"].default_value = 1.0
        else:
            nt.links.new(socket, vm.inputs["Scale"])
        return vm.outputs[0]

    sig = np.array(sigma_rgb, float)
    nt.links.new(scaled(sig * albedo, sigma), vc.inputs["Scatter Coefficients"])
    nt.links.new(scaled(sig * (1.0 - albedo), sigma), vc.inputs["Absorption Coefficients"])
    if emission is not None:
        nt.links.new(scaled(emission, raw), vc.inputs["Emission Coefficients"])
    else:
        vc.inputs["Emission Coefficients"].default_value = (0.0, 0.0, 0.0)
    nt.links.new(vc.outputs[0], out.inputs["Volume"])
    return mat


def _constant(nt, value):
    v = nt.nodes.new("ShaderNodeValue")
    v.outputs[0].default_value = float(value)
    return v.outputs[0]


def _math(nt, op, a, b=None):
    m = nt.nodes.new("ShaderNodeMath")
    m.operation = op
    for i, x in enumerate((a, b)):
        if x is None:
            continue
        if isinstance(x, (int, float)):
            m.inputs[i].default_value = float(x)
        else:
            nt.links.new(x, m.inputs[i])
    return m.outputs[0]


def _mesh_object(bpy, name, points, tris, to_world, material):
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(map(float, p)) for p in points], [], [tuple(map(int, t)) for t in tris])
    me.update()
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    ob.matrix_world = _mat(C @ to_world)
    ob.data.materials.append(material)
    return ob


def build(bpy, scene: S.BenchScene, vdb_dir: str):
    sc = bpy.context.scene
    cam_d = bpy.data.cameras.new("camera")
    cam_d.type = "PERSP"
    cam_d.sensor_fit = "HORIZONTAL"
    cam_d.angle = math.radians(scene.camera.fov_x_deg)
    cam_d.clip_start = scene.camera.near
    cam_d.clip_end = scene.camera.far
    cam_d.shift_x = cam_d.shift_y = 0.0
    cam = bpy.data.objects.new("camera", cam_d)
    sc.collection.objects.link(cam)
    cam.matrix_world = _mat(C @ scene.camera.to_world())
    sc.camera = cam

    world = bpy.data.worlds.new("world")
    sc.world = world
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0

    for s in scene.surfaces:
        _mesh_object(bpy, s.name, s.points, s.tris, s.to_world, _diffuse_material(bpy, s.name, s.albedo))

    for m in scene.media:
        if isinstance(m, S.BoxMedium):
            mat = _volume_material(bpy, m.name, m.albedo, m.phase,
                                   lambda nt, st=m.sigma_t: (_constant(nt, st), None))
            _mesh_object(bpy, m.name, S.BOX_POINTS, S.BOX_TRIS, m.to_world, mat)
        elif isinstance(m, S.GridMedium):
            vol = bpy.data.volumes.new(m.name)
            vol.filepath = os.path.join(vdb_dir, m.file)
            vol.render.precision = "FULL"
            vol.render.clipping = 0.0
            vol.render.space = "WORLD"

            def dens(nt, scale=m.density_scale):
                attr = nt.nodes.new("ShaderNodeAttribute")
                attr.attribute_name = "density"
                raw = attr.outputs["Fac"]
                return _math(nt, "MULTIPLY", raw, scale), raw

            mat = _volume_material(bpy, m.name, m.albedo, m.phase, dens, emission=m.emission)
            ob = bpy.data.objects.new(m.name, vol)
            sc.collection.objects.link(ob)
            ob.matrix_world = _mat(C @ m.to_world)
            ob.data.materials.append(mat)
        elif isinstance(m, S.ExponentialMedium):
            def dens(nt, md=m):
                geo = nt.nodes.new("ShaderNodeNewGeometry")
                sep = nt.nodes.new("ShaderNodeSeparateXYZ")
                nt.links.new(geo.outputs["Position"], sep.inputs[0])
                h = sep.outputs["Z"]  # Blender Z = USD Y = height
                e = _math(nt, "EXPONENT", _math(nt, "MULTIPLY", h, -md.b))
                return _math(nt, "MULTIPLY", e, md.density * md.a), None

            mat = _volume_material(bpy, m.name, m.albedo, m.phase, dens, sigma_rgb=m.extinction_color)
            _mesh_object(bpy, m.name, S.BOX_POINTS, S.BOX_TRIS, S.box_to_world(m.lo, m.hi), mat)
        else:
            raise TypeError(m)

    for i, l in enumerate(scene.lights):
        if isinstance(l, S.Dome):
            bg.inputs["Color"].default_value = (*map(float, l.radiance), 1.0)
        elif isinstance(l, S.Distant):
            ld = bpy.data.lights.new("sun%d" % i, type="SUN")
            e = max(l.irradiance)
            ld.energy = float(e)
            ld.color = tuple(float(c / e) for c in l.irradiance)
            ld.angle = 0.0
            ob = bpy.data.objects.new("sun%d" % i, ld)
            sc.collection.objects.link(ob)
            ob.matrix_world = _mat(C @ S.frame_z_to(l.direction))
        elif isinstance(l, S.Spot):
            ld = bpy.data.lights.new("spot%d" % i, type="SPOT")
            e = max(l.intensity)
            ld.energy = float(4.0 * math.pi * e)
            ld.color = tuple(float(c / e) for c in l.intensity)
            ld.spot_size = 2.0 * math.radians(l.cone_deg)
            ld.spot_blend = 0.0
            ld.shadow_soft_size = 0.0
            if hasattr(ld, "use_soft_falloff"):
                ld.use_soft_falloff = False
            ob = bpy.data.objects.new("spot%d" % i, ld)
            sc.collection.objects.link(ob)
            ob.matrix_world = _mat(C @ S.translate(l.position) @ S.frame_z_to(l.direction))
        else:
            raise TypeError(l)


class _Stats:
    """Timestamps of Cycles' render_stats status messages during one render."""

    def __init__(self, bpy):
        self.bpy = bpy
        self.msgs = []
        self.t0 = 0.0

    def __enter__(self):
        self.t0 = time.perf_counter()
        self.msgs = []
        self.bpy.app.handlers.render_stats.append(self._on)
        return self

    def __exit__(self, *exc):
        self.bpy.app.handlers.render_stats.remove(self._on)

    def _on(self, text, *unused):
        self.msgs.append((time.perf_counter() - self.t0, str(text)))

    def summary(self, total):
        def status(m):
            parts = [p.strip() for p in m.split("|")]
            parts = [p for p in parts if not p.startswith("Mem:") and not p.startswith("Remaining:")]
            return " | ".join(parts)

        first_sample = next((t for t, m in self.msgs if "Sample 0/" in m), None)
        finished = next((t for t, m in self.msgs if status(m).startswith("Finished")), None)
        if finished is None:
            finished = next((t for t, m in reversed(self.msgs) if "Sample " in m), total)
        vol_start = vol_end = None
        for t, m in self.msgs:
            phase = status(m).split(" | ")[0]
            if phase == "Updating Volume" and vol_start is None:
                vol_start = t
            elif vol_start is not None and vol_end is None and phase != "Updating Volume":
                vol_end = t
        return {"setup_seconds": first_sample if first_sample is not None else float("nan"),
                "sampling_seconds": (finished - first_sample) if first_sample is not None else total,
                "volume_preprocess_seconds": (vol_end - vol_start) if vol_start is not None and vol_end else 0.0,
                "wall_seconds": total}


def render_once(bpy, scene, a, spp, seed, path):
    _reset()
    sc = configure(bpy, scene, a.size[0], a.size[1], spp, seed, a.threads)
    build(bpy, scene, a.vdb_dir)
    sc.render.filepath = path
    with _Stats(bpy) as st:
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        total = time.perf_counter() - t0
    info = st.summary(total)
    img = bpy.data.images.load(path)
    img.colorspace_settings.name = "Non-Color"
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float32).reshape(h, w, 4)[::-1, :, :3]
    bpy.data.images.remove(img)
    os.remove(path)
    return np.ascontiguousarray(px), info


def _prepare(a):
    scene = S.get(a.scene)
    why = unsupported(scene)
    if why:
        raise SystemExit("SKIP: " + "; ".join(why))
    import bpy

    os.makedirs(os.path.join(OUT, "cycles"), exist_ok=True)
    return bpy, scene


def cmd_render(a) -> int:
    bpy, scene = _prepare(a)
    tmp = os.path.join(OUT, "cycles", "%s_%d.exr" % (a.scene, os.getpid()))
    # Warm-up (kernel load, caches; excluded) that also measures the sampling time per sample.
    _, warm = render_once(bpy, scene, a, 8, 999, tmp)
    per_spp = max(warm["sampling_seconds"], 1e-4) / 8
    budgets = sorted(float(b) for b in a.budgets.split(","))
    times, spps, images, infos = [], [], [], []
    # One render per budget; the sample count comes from the sampling speed measured so far (the
    # largest render is the best estimate); one more render if the last budget was still missed.
    queue = list(budgets)
    extra = 0
    while queue:
        b = queue.pop(0)
        spp = max(1, min(a.max_spp, int(round(b / per_spp))))
        if spps and spp <= spps[-1]:
            continue
        img, info = render_once(bpy, scene, a, spp, a.seed * 1000 + len(times), tmp)
        times.append(info["sampling_seconds"])
        spps.append(spp)
        images.append(img)
        infos.append(info)
        per_spp = max(info["sampling_seconds"], 1e-4) / spp
        if not queue and info["sampling_seconds"] < 0.9 * budgets[-1] and extra < 2 and spp < a.max_spp:
            queue.append(budgets[-1] * 1.05)
            extra += 1
    np.savez_compressed(a.out, times=np.array(times), spp=np.array(spps), images=np.array(images),
                        meta=json.dumps({"blender": bpy.app.version_string, "renders": infos, "warmup": warm}))
    return 0


def cmd_reference(a) -> int:
    bpy, scene = _prepare(a)
    tmp = os.path.join(OUT, "cycles", "%s_ref_%d.exr" % (a.scene, os.getpid()))
    _, info = render_once(bpy, scene, a, 16, 7, tmp)
    per_spp = max(info["sampling_seconds"], 1e-3) / 16
    spp = max(16, int(a.seconds / a.batches / per_spp))
    batches, infos = [], []
    t0 = time.perf_counter()
    for b in range(a.batches):
        img, info = render_once(bpy, scene, a, spp, 5000 + b, tmp)
        batches.append(img)
        infos.append(info)
    batches = np.array(batches, dtype=np.float64)
    np.savez_compressed(a.out, mean=batches.mean(axis=0).astype(np.float32), batches=batches.astype(np.float32),
                        meta=json.dumps({"blender": bpy.app.version_string, "spp": spp * a.batches,
                                         "seconds": time.perf_counter() - t0, "renders": infos}))
    return 0


def cmd_check(a) -> int:
    try:
        import bpy

        ok = bpy.app.version >= (4, 5, 0)
        why = "" if ok else "Blender %s has no Volume Coefficients node (needs >= 4.5)" % bpy.app.version_string
        print(json.dumps({"available": ok, "version": bpy.app.version_string, "why": why}))
    except Exception as e:  # noqa: BLE001 - report why, never fail the benchmark
        print(json.dumps({"available": False, "why": "%s: %s" % (type(e).__name__, e)}))
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    for name in ("render", "reference"):
        p = sub.add_parser(name)
        p.add_argument("--scene", required=True)
        p.add_argument("--size", nargs=2, type=int, default=(80, 60))
        p.add_argument("--threads", type=int, default=2)
        p.add_argument("--seed", type=int, default=0)
        p.add_argument("--vdb-dir", default=os.path.join(REPO, "testenv", "bench"))
        p.add_argument("--out", required=True)
    sub.choices["render"].add_argument("--budgets", required=True)
    sub.choices["render"].add_argument("--max-spp", type=int, default=1 << 16)
    sub.choices["reference"].add_argument("--seconds", type=float, default=30.0)
    sub.choices["reference"].add_argument("--batches", type=int, default=8)
    sub.add_parser("check")
    a = ap.parse_args(argv)
    return {"render": cmd_render, "reference": cmd_reference, "check": cmd_check}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
