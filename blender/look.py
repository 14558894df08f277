"""The look against Cycles (issue 61): physically based objects (textured, metallic and rough
parts) under an HDR world, both renders linear (no tone mapping), equirect 256 × 128 per eye;
Cycles at 128 samples. Prints the mean linear colour of the objects' pixels on each side and
the per-pixel mean |Δ|, overall and per object (which part differs, by how much).

    python blender/look.py [OUT_DIR [TURN_DEG]]   (a Python with bpy 4.5 and twister's package;
    TURN_DEG turns the world's map about Z with a Mapping node)"""

import json
import math
import pathlib
import sys
import tempfile

import numpy as np

import bpy

HERE = pathlib.Path(__file__).resolve().parent
sys.path[:0] = [str(HERE)]
import twister_blender  # noqa: E402
from twister_blender import ops  # noqa: E402

W, H = 256, 128


def write_hdr(path, w=128, h=64):
    """A sky (blue above, warm ground below) with a small bright sun, as a Radiance .hdr."""
    y = (np.arange(h) + 0.5) / h
    x = (np.arange(w) + 0.5) / w
    alt = (0.5 - y)[:, None] * math.pi
    sky = np.where(alt > 0, 1.0, 0.0)[..., None] * np.array([0.35, 0.55, 1.0]) * (0.6 + 0.6 * np.sin(np.maximum(alt, 0)))[..., None]
    ground = np.where(alt <= 0, 1.0, 0.0)[..., None] * np.array([0.45, 0.32, 0.2]) * 0.5
    rgb = np.broadcast_to(sky + ground, (h, w, 3)).copy()
    az = (x - 0.5) * 2 * math.pi
    sun = (np.abs(alt - 0.6) < 0.12) & (np.abs(az[None, :] - 0.8) < 0.12)
    rgb[sun] = [40.0, 36.0, 30.0]
    m = rgb.max(axis=2)
    e = np.where(m > 1e-32, np.ceil(np.log2(np.maximum(m, 1e-32))), -128)
    mant = np.where(m[..., None] > 1e-32, rgb / np.exp2(e)[..., None] * 256, 0)
    rgbe = np.concatenate([np.clip(mant, 0, 255), (e + 128)[..., None]], axis=2).astype(np.uint8)
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + f"-Y {h} +X {w}\n".encode())
        f.write(rgbe.tobytes())


def checker(name, a, b, n=8, size=128):
    img = bpy.data.images.new(name, size, size)
    u = (np.arange(size) * n // size)
    mask = (u[:, None] + u[None, :]) % 2 == 0
    px = np.where(mask[..., None], np.array([*a, 1.0]), np.array([*b, 1.0])).astype(np.float32)
    img.pixels[:] = px.ravel()
    img.filepath_raw = str(pathlib.Path(tempfile.gettempdir()) / f"{name}.png")
    img.file_format = "PNG"
    img.save()
    return img


def pbr(name, metallic, roughness, texture=None, colour=(0.8, 0.8, 0.8)):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Base Color"].default_value = (*colour, 1)
    if texture is not None:
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.image = texture
        nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def build(env_path, turn_deg=0.0):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if not hasattr(bpy.types.Scene, "twister"):
        twister_blender.register()
    objects = [
        ("metal", (0.0, 2.0, 0.0), pbr("metal", 1.0, 0.3, checker("gold", (0.9, 0.7, 0.3), (0.6, 0.6, 0.6)))),
        ("plastic", (-1.6, 1.4, -0.2), pbr("plastic", 0.0, 0.6, checker("red", (0.7, 0.1, 0.1), (0.9, 0.9, 0.9)))),
        ("rough", (1.7, 1.2, 0.1), pbr("rough", 0.0, 0.9, colour=(0.2, 0.5, 0.25))),
    ]
    for name, loc, mat in objects:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=loc, segments=64, ring_count=32)
        bpy.ops.object.shade_smooth()
        obj = bpy.context.active_object
        obj.name = name
        obj.data.materials.append(mat)
    world = bpy.data.worlds.new("hdr")
    world.use_nodes = True
    env = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(env_path)
    world.node_tree.links.new(env.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])
    if turn_deg:
        coords = world.node_tree.nodes.new("ShaderNodeTexCoord")
        mapping = world.node_tree.nodes.new("ShaderNodeMapping")
        mapping.inputs["Rotation"].default_value[2] = math.radians(turn_deg)
        world.node_tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        world.node_tree.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    scene = bpy.context.scene
    scene.world = world
    data = bpy.data.cameras.new("pano")
    data.type = "PANO"
    data.panorama_type = "EQUIRECTANGULAR"
    data.stereo.interocular_distance = 0.064
    data.stereo.use_spherical_stereo = True
    cam = bpy.data.objects.new("camera", data)
    scene.collection.objects.link(cam)
    cam.rotation_euler = (math.radians(90), 0, 0)
    scene.camera = cam
    return [name for name, _, _ in objects]


def cycles_left(out):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 128
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = W, H, 100
    scene.render.use_multiview = True
    scene.render.views_format = "STEREO_3D"
    scene.render.views["right"].use = False  # the left eye alone: a single-layer float image
    scene.render.image_settings.file_format = "HDR"
    scene.render.filepath = f"{out}/cycles"
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(f"{out}/cycles_L.hdr")
    px = np.array(img.pixels[:], dtype=np.float32).reshape(H, W, 4)[::-1, :, :3]
    return px


def measure(out, turn_deg=0.0):
    """Renders the look scene both ways (the world turned `turn_deg` about Z by a Mapping node)
    and returns the comparison: means, mean |Δ| over the mean, per object and for the
    background."""
    env_path = f"{out}/sky.hdr"
    pathlib.Path(out).mkdir(parents=True, exist_ok=True)
    write_hdr(env_path)
    build(env_path, turn_deg)
    scene = bpy.context.scene
    t = scene.twister
    t.width, t.samples = W, "16"
    path, settings, _, warnings, tmp = ops.prepare(bpy.context)
    import twister

    with tmp:
        frame = twister.Renderer().render(path, **dict(settings, hdr=True, depth=True))
    ours = frame.hdr[0]
    seen = np.isfinite(frame.depth[0])
    theirs = cycles_left(out)
    result = {"warnings": warnings, "settings": {k: v for k, v in settings.items() if k != "environment"}}
    a, b = ours[seen], theirs[seen]
    result["objects_pixels"] = int(seen.sum())
    result["mean_twister"] = a.mean(axis=0).tolist()
    result["mean_cycles"] = b.mean(axis=0).tolist()
    result["mean_ratio"] = float(a.mean() / b.mean())
    result["mean_abs_diff_over_mean"] = float(np.abs(a - b).mean() / b.mean())
    bg = ~seen
    result["background_ratio"] = float(ours[bg].mean() / theirs[bg].mean())
    result["background_mean_abs_diff_over_mean"] = float(np.abs(ours[bg] - theirs[bg]).mean() / theirs[bg].mean())
    np.save(f"{out}/twister.npy", ours)
    np.save(f"{out}/cycles.npy", theirs)
    # Per object: by azimuth (the objects stand apart), the columns each covers.
    per_object = {}
    az = ((np.arange(W) + 0.5) / W - 0.5) * 360
    for name, centre in [("metal", 0.0), ("plastic", 48.8), ("rough", -54.8)]:
        m = seen & (np.abs(az - centre) < 20)[None, :]
        per_object[name] = {
            "pixels": int(m.sum()),
            "ratio": float(ours[m].mean() / theirs[m].mean()),
            "mean_abs_diff_over_mean": float(np.abs(ours[m] - theirs[m]).mean() / theirs[m].mean()),
        }
    result["per_object"] = per_object
    return result


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp()
    turn = float(sys.argv[2]) if len(sys.argv) > 2 else 0.0
    print(json.dumps(measure(out, turn), indent=2), flush=True)
    # Blender as a module hangs on its way out while any Python class is still registered.
    twister_blender.unregister()


if __name__ == "__main__":
    main()
