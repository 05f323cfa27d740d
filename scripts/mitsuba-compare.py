#!/usr/bin/env python3
"""Path tracing speed and noise: Arbor against Mitsuba 3 on the METU CENG 795 Cornell boxes.

Each METU scene (XML) is translated into a Mitsuba scene dict -- same camera, triangles and spheres,
Lambertian albedo, glass and mirrors, mesh/sphere lights and point lights, path length -- and rendered
with Mitsuba's `path` integrator in its `scalar_rgb` and `llvm_ad_rgb` variants (the LLVM one once
untimed first, to compile), and with `arbor render --integrator path --path-options mis` (the same
estimator as Mitsuba's: cosine-sampled bounces and light samples weighted by MIS, one lobe of a glass
picked at random; --arbor-path-options picks another, '' the scene's RendererParams, which also follow
both lobes of glass as the course's renderer does: unbiased either way), at the same samples per pixel
on each thread count. For every render it prints samples per second (width x height x spp / seconds
of rendering, scene loading excluded; Arbor's `render_ms` of its `--stats-json`), the RMSE in
linear radiance against a high-spp render of each renderer (cached in --cache, rendered with another
seed) and the 1-minute load average (the machine may be shared), then a Markdown table for
docs/performance.md. When the scene's `../outputs/` folder holds the official image its camera names,
Mitsuba's high-spp render is compared with it too (each divided by its mean; per pixel, and in 16x16
blocks, which averages away most of the official image's own noise).

Setup: `pip install mitsuba`; the LLVM variant needs a recent libLLVM (Debian: `apt-get install
libllvm19`; LIBLLVM below is used when DRJIT_LIBLLVM_PATH is unset and the file exists). Run:

    scripts/mitsuba-compare.py --arbor target/release/arbor --spp 64 --threads 1,2 \\
        /work/shared/scenes/ceng795-2022/hw6/pathTracing/inputs/cornellbox_jaroslav_path_glass.xml:5

What is translated: materials with SpecularReflectance 0 (any BRDF, or none) become Mitsuba `diffuse`
with reflectance DiffuseReflectance; `dielectric` becomes `dielectric` (RefractionIndex; an
AbsorptionCoefficient is dropped with a note); `mirror` becomes a `conductor` with
specular_reflectance MirrorReflectance, or with a DiffuseReflectance too (Arbor's sum of the two parts) a
`blendbsdf` of the two, each divided by its weight. A dielectric's or mirror's SpecularReflectance (a Phong lobe
beside the delta lobes, which neither Mitsuba BSDF has) is dropped with a note for both renderers:
Arbor renders a copy of the scene without it (in --cache). A `LightMesh`/`LightSphere` Radiance is a Mitsuba `area`
emitter (one-sided, on the side the triangle winding faces), a `PointLight` a `point` emitter.
MaxRecursionDepth D is Mitsuba max_depth D + 2 unless --max-depth is given (it changes Mitsuba only):
Mitsuba counts the camera ray as segment 1, the course's renderers recurse D times after the primary
hit and connect each hit to a light, and D + 2 is what matches the official hw6 path-traced images.
Russian roulette is off (rr_depth = max_depth), unless Arbor's camera has one (`roulette` in
--arbor-path-options, or a camera naming RussianRoulette rendered with the scene's RendererParams): Arbor
then runs its unbiased roulette (`--roulette unbiased`: the course's, which a camera's RussianRoulette
otherwise gets, is biased) with no depth limit but its cap of 256 bounces, and Mitsuba its own roulette
(rr_depth 5) with max_depth 258, the same estimand. Mitsuba's sampler is `independent` (its default)
unless --mitsuba-sampler names another: `multijitter` or `stratified` stratify every dimension of a
path and lower Mitsuba's noise at 64 spp by about a third; Arbor's default (`stratified`) stratifies
its light and bounce samples too, `--arbor-sampler independent` only the pixel position. A flat-shaded PLY mesh
(`<Faces plyFile=...>`) is read by Mitsuba from the same file, with the object's transformation, and so is a
`MeshInstance` of it. Anything else (a specular lobe, textures, smooth shading, non-uniformly scaled spheres,
a lens, `AreaLight`, a square that no ray meets) is refused with its reason and the scene skipped.

The mesh-heavy scene: `igea-box:diffuse` or `igea-box:glass` as a SCENE argument generates (into --cache)
the hw6 diffuse Cornell box with its spheres replaced by igea.ply (269k triangles) in white Lambertian or
clear glass, from $ARBOR_SCENES and $ARBOR_MESHES (default ../shared/scenes, ../shared/meshes; the mesh is
referenced, not copied):

    ARBOR_SCENES=/work/shared/scenes ARBOR_MESHES=/work/shared/meshes scripts/mitsuba-compare.py \\
        --spp 64 --threads 1,2 --variants llvm_ad_rgb --ref-spp 256 igea-box:diffuse igea-box:glass

Veach's door: `veach-ajar` as a SCENE argument generates (into --cache) `hw6/veach-ajar` (from $ARBOR_SCENES;
21 objects, 382,624 triangles; camera 2, 1280x720, MaxRecursionDepth 6) as both renderers can render it:
each texture replaced by its mean colour, the Phong lobes and the glass pots' absorption dropped, and the
square `AreaLight` made two `LightMesh` quads back to back (geometry, as Mitsuba's emitters are). The
script prints these notes.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LIBLLVM):
    os.environ["DRJIT_LIBLLVM_PATH"] = LIBLLVM

import drjit as dr  # noqa: E402  (after DRJIT_LIBLLVM_PATH)
import mitsuba as mi  # noqa: E402

# The variant used for references, official-image checks and reading EXR files.
REF_VARIANT = "llvm_ad_rgb"
# Arbor's cap on the bounces of a path under Russian roulette (integrator/path.rs MAX_BOUNCES).
ARBOR_MAX_BOUNCES = 256


class Unsupported(Exception):
    """A scene feature with no faithful Mitsuba translation."""


# ---------------------------------------------------------------------------------------------
# METU XML -> a plain description (numpy), independent of the Mitsuba variant


def floats(text):
    return [float(x) for x in (text or "").split()]


def child_floats(node, name, default=None):
    c = node.find(name)
    if c is None:
        if default is None:
            raise Unsupported(f"<{node.tag} id={node.get('id')}> has no <{name}>")
        return default
    return floats(c.text)


def read_transforms(root):
    """Named 4x4 matrices: t1 (Translation), s1 (Scaling), r1 (Rotation, degrees), c1 (Composite)."""
    out = {}
    block = root.find("Transformations")
    for n in [] if block is None else list(block):
        v = floats(n.text)
        m = np.eye(4)
        if n.tag == "Translation":
            m[:3, 3] = v
        elif n.tag == "Scaling":
            m[:3, :3] = np.diag(v)
        elif n.tag == "Rotation":
            angle, axis = math.radians(v[0]), np.array(v[1:4]) / np.linalg.norm(v[1:4])
            k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
            m[:3, :3] = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
        elif n.tag == "Composite":
            m = np.array(v).reshape(4, 4)  # rows, as written
        else:
            continue
        out[n.tag[0].lower() + n.get("id").strip()] = m
    return out


def object_transform(node, transforms):
    """The object's `Transformations` list composed left to right (the first listed applies first)."""
    m = np.eye(4)
    t = node.find("Transformations")
    for name in [] if t is None else t.text.split():
        m = transforms[name] @ m
    return m


def read_material(mat, notes):
    """A METU material element as a Mitsuba BSDF dict; what is dropped is appended to notes."""
    mid = mat.get("id")
    kind = (mat.get("type") or "").strip()
    if kind == "dielectric":
        if any(child_floats(mat, "AbsorptionCoefficient", [0.0])):
            notes.append(f"material {mid}: AbsorptionCoefficient dropped (Mitsuba `dielectric` has none)")
        return {"type": "dielectric", "int_ior": child_floats(mat, "RefractionIndex")[0], "ext_ior": 1.0}
    if kind == "mirror":
        kr = child_floats(mat, "MirrorReflectance")
        mirror = {"type": "conductor", "material": "none", "specular_reflectance": {"type": "rgb", "value": kr}}
        kd = child_floats(mat, "DiffuseReflectance", [0.0, 0.0, 0.0])
        if not any(kd):
            return mirror
        # Arbor's mirror with a diffuse colour is the sum k_d/pi + k_r delta, its bounce picking a part by
        # luminance; Mitsuba's blendbsdf is (1 - w) f_0 + w f_1, so each part is divided by its share.
        w = luminance(kr) / (luminance(kd) + luminance(kr))
        mirror["specular_reflectance"]["value"] = [c / w for c in kr]
        return {"type": "blendbsdf", "weight": w, "bsdf_0": {
            "type": "diffuse", "reflectance": {"type": "rgb", "value": [c / (1 - w) for c in kd]}}, "bsdf_1": mirror}
    if kind:
        raise Unsupported(f"material {mid}: type '{kind}' is not translated")
    if any(child_floats(mat, "SpecularReflectance", [0.0])):
        raise Unsupported(f"material {mid}: a specular lobe (SpecularReflectance > 0); Mitsuba 3 has no Phong "
                          "BRDF, only diffuse surfaces (SpecularReflectance 0) are translated")
    for legacy in ("Transparency", "MirrorReflectance"):
        if any(child_floats(mat, legacy, [0.0])):
            raise Unsupported(f"material {mid}: untyped with {legacy} (legacy glass/mirror) is not translated")
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": child_floats(mat, "DiffuseReflectance")}}


def luminance(c):
    """Rec. 709 luminance, Arbor's (tonemap::luminance)."""
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]


def write_ply(path, vertices, faces):
    """A binary PLY of triangles (no normals: Mitsuba shades it flat, as the METU meshes are)."""
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rows["n"], rows["i"] = 3, faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(np.asarray(vertices, dtype="<f4").tobytes())
        f.write(rows.tobytes())


def read_camera(root, camera_id):
    cams = root.findall("Cameras/Camera")
    if not cams:
        raise Unsupported("no <Camera>")
    cam = cams[0] if camera_id is None else next((c for c in cams if c.get("id").strip() == camera_id), None)
    if cam is None:
        raise Unsupported(f"no camera with id {camera_id}")
    for absent in ("FocusDistance", "ApertureSize", "Transformations"):
        if cam.find(absent) is not None:
            raise Unsupported(f"camera {cam.get('id')}: <{absent}> is not translated")
    pos = np.array(child_floats(cam, "Position"))
    gaze = (np.array(child_floats(cam, "GazePoint")) - pos if cam.find("GazePoint") is not None
            else np.array(child_floats(cam, "Gaze")))
    width, height = (int(x) for x in child_floats(cam, "ImageResolution"))
    if (cam.get("type") or "").strip() == "lookAt":
        fov_y = child_floats(cam, "FovY")[0]
    else:
        left, right, bottom, top = child_floats(cam, "NearPlane")[:4]
        if not (math.isclose(left, -right) and math.isclose(bottom, -top)):
            raise Unsupported("an off-centre <NearPlane> window is not translated")
        fov_y = math.degrees(2 * math.atan(top / child_floats(cam, "NearDistance")[0]))
    path_traced = (cam.findtext("Renderer") or "").strip() == "PathTracing"
    params = (cam.findtext("RendererParams") or "").split() if path_traced else []
    return {"id": cam.get("id").strip(), "position": pos, "gaze": gaze, "up": np.array(child_floats(cam, "Up")),
            "fov_y": fov_y, "width": width, "height": height, "path_traced": path_traced,
            "roulette": "RussianRoulette" in params,
            "left_handed": (cam.get("handedness") or "right").strip() == "left",
            "image_name": cam.find("ImageName").text.strip()}


def arbor_roulette(path, camera_id, args):
    """Whether Arbor's render of the camera ends its paths by Russian roulette (the unbiased one: the script
    passes --roulette unbiased), as --arbor-integrator and --arbor-path-options make it."""
    if args.arbor_integrator and args.arbor_path_options:
        return "roulette" in args.arbor_path_options.split(",")
    if args.arbor_integrator not in ("", "path"):
        return False
    return read_camera(ET.parse(path).getroot(), camera_id)["roulette"]


def metu_to_mitsuba(path, camera_id, spp, max_depth, tmp, sampler="independent", roulette=False):
    """(Mitsuba scene dict, camera, max_depth, notes) for `path` (call with a variant set); PLY files go to tmp.
    With `roulette`, Mitsuba's own Russian roulette and Arbor's cap on path length, as Arbor's unbiased
    roulette has them."""
    notes = []
    root = ET.parse(path).getroot()
    if any(child_floats(root, "BackgroundColor", [0.0])):
        raise Unsupported("a non-black BackgroundColor is not translated")
    for tex in ("Textures", "Images", "TextureMap"):
        if root.find(tex) is not None:
            raise Unsupported(f"<{tex}> is not translated")
    cam = read_camera(root, camera_id)
    verts = np.array(floats(root.findtext("VertexData")), dtype=float).reshape(-1, 3)
    transforms = read_transforms(root)
    materials = {m.get("id").strip(): m for m in root.findall("Materials/Material")}
    if max_depth is None:
        max_depth = ARBOR_MAX_BOUNCES + 2 if roulette else int(root.findtext("MaxRecursionDepth", "0")) + 2
    rr_depth = 5 if roulette else max_depth

    to_world = mi.ScalarTransform4f().look_at(origin=cam["position"].tolist(),
                                              target=(cam["position"] + cam["gaze"]).tolist(),
                                              up=cam["up"].tolist())
    if cam["left_handed"]:
        to_world = to_world @ mi.ScalarTransform4f().scale([-1, 1, 1])
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth, "rr_depth": rr_depth, "hide_emitters": False},
        "sensor": {"type": "perspective", "fov_axis": "y", "fov": cam["fov_y"], "to_world": to_world,
                   "sampler": {"type": sampler, "sample_count": spp},
                   "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"],
                            "pixel_format": "rgb", "rfilter": {"type": "box"}}},
    }

    objects = root.find("Objects")
    meshes = {o.get("id").strip(): o for o in ([] if objects is None else objects.findall("Mesh"))}
    for k, obj in enumerate([] if objects is None else list(objects)):
        material = obj
        if obj.tag == "MeshInstance":
            # The base mesh's triangles under the instance's transform, after the base's own unless reset.
            base = meshes.get((obj.get("baseMeshId") or "").strip())
            if base is None:
                raise Unsupported(f"MeshInstance {obj.get('id')}: its base is not a <Mesh>")
            m = object_transform(obj, transforms)
            if (obj.get("resetTransform") or "false").strip() != "true":
                m = m @ object_transform(base, transforms)
            shape = shape_of(base, verts, transforms, tmp / f"{k}.ply", Path(path).parent, m)
            material = obj if obj.find("Material") is not None else base
        else:
            shape = shape_of(obj, verts, transforms, tmp / f"{k}.ply", Path(path).parent)
        shape["bsdf"] = read_material(materials[material.findtext("Material").strip()], notes)
        if obj.tag.startswith("Light"):
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": child_floats(obj, "Radiance")}}
        scene[f"{obj.tag}_{obj.get('id')}"] = shape

    lights = root.find("Lights")
    for light in [] if lights is None else list(lights):
        if light.tag == "AmbientLight":
            if any(floats(light.text)):
                notes.append("AmbientLight dropped (no counterpart in a path tracer)")
        elif light.tag == "PointLight" and light.find("Transformations") is None:
            scene[f"PointLight_{light.get('id')}"] = {
                "type": "point", "position": child_floats(light, "Position"),
                "intensity": {"type": "rgb", "value": child_floats(light, "Intensity")}}
        else:
            raise Unsupported(f"<{light.tag}> is not translated")
    return scene, cam, max_depth, notes


def shape_of(obj, verts, transforms, ply_path, scene_dir, m=None):
    """A Mitsuba shape dict (without BSDF) for a Mesh/LightMesh/Sphere/LightSphere element (a PLY mesh's
    file relative to scene_dir), under the 4x4 matrix m (default: the object's own transformations)."""
    m = object_transform(obj, transforms) if m is None else m
    if obj.tag in ("Sphere", "LightSphere"):
        linear = m[:3, :3]
        scale = abs(np.linalg.det(linear)) ** (1 / 3)
        if not np.allclose(linear.T @ linear, scale**2 * np.eye(3), rtol=1e-5, atol=1e-6):
            raise Unsupported(f"{obj.tag} {obj.get('id')}: a non-uniformly scaled sphere is not translated")
        centre = m @ np.append(verts[int(obj.findtext("Center")) - 1], 1.0)
        return {"type": "sphere", "center": centre[:3].tolist(), "radius": float(obj.findtext("Radius")) * scale}
    if obj.tag not in ("Mesh", "LightMesh"):
        raise Unsupported(f"<{obj.tag}> is not translated")
    faces_node = obj.find("Faces")
    if obj.get("shadingMode", "flat").strip() != "flat":
        raise Unsupported(f"{obj.tag} {obj.get('id')}: only flat-shaded meshes are translated")
    if faces_node.get("plyFile"):
        # Mitsuba reads the PLY itself; face normals, as Arbor shades a flat mesh.
        return {"type": "ply", "filename": str(scene_dir / faces_node.get("plyFile").strip()), "face_normals": True,
                "to_world": mi.ScalarTransform4f(m.tolist())}
    ids = np.array(floats(faces_node.text), dtype=int).reshape(-1, 3) + int(faces_node.get("vertexOffset", "0"))
    used, faces = np.unique(ids, return_inverse=True)
    local = (m @ np.c_[verts[used - 1], np.ones(len(used))].T).T[:, :3]
    write_ply(ply_path, local, faces.reshape(-1, 3))
    return {"type": "ply", "filename": str(ply_path), "face_normals": True}


# ---------------------------------------------------------------------------------------------
# The mesh-heavy scene: igea.ply (269k triangles) in the hw6 Cornell box, generated from the shared files

# The materials the bust gets: a white Lambertian one, or clear glass (index 1.5, no absorption, so that
# the translation drops nothing).
IGEA_MATERIALS = {
    "diffuse": ("", "<DiffuseReflectance>0.8 0.8 0.8</DiffuseReflectance>"),
    "glass": ("dielectric", "<DiffuseReflectance>0 0 0</DiffuseReflectance><RefractionIndex>1.5</RefractionIndex>"
                            "<AbsorptionCoefficient>0 0 0</AbsorptionCoefficient>"),
}


def igea_box(kind, out_dir):
    """Writes `igea_box_<kind>.xml` into out_dir and returns its path: `cornellbox_jaroslav_path_diffuse.xml`
    (from $ARBOR_SCENES, default ../shared/scenes) with camera 1 only and its two spheres replaced by
    $ARBOR_MESHES/igea.ply (default ../shared/meshes), referenced by its absolute path, never copied: scaled
    12x (1.2 high), stood up on the floor facing the camera, of material `kind` (IGEA_MATERIALS)."""
    if kind not in IGEA_MATERIALS:
        raise Unsupported(f"igea-box:{kind}: the material is one of {', '.join(IGEA_MATERIALS)}")
    scenes = Path(os.environ.get("ARBOR_SCENES", "../shared/scenes"))
    template = scenes / "ceng795-2022/hw6/pathTracing/inputs/cornellbox_jaroslav_path_diffuse.xml"
    igea = Path(os.environ.get("ARBOR_MESHES", "../shared/meshes")) / "igea.ply"
    for f in (template, igea):
        if not f.is_file():
            raise Unsupported(f"{f} is absent (set ARBOR_SCENES and ARBOR_MESHES)")
    root = ET.parse(template).getroot()
    cameras = root.find("Cameras")
    for cam in cameras.findall("Camera")[1:]:
        cameras.remove(cam)
    objects = root.find("Objects")
    for sphere in objects.findall("Sphere"):
        objects.remove(sphere)
    kind_attr, body = IGEA_MATERIALS[kind]
    material = ET.fromstring(f'<Material id="100"{f" type={chr(34)}{kind_attr}{chr(34)}" if kind_attr else ""}>'
                             f"<AmbientReflectance>0 0 0</AmbientReflectance>{body}<SpecularReflectance>0 0 0</SpecularReflectance>"
                             "</Material>")
    root.find("Materials").append(material)
    # The bust's y axis (its height, -0.0497..0.0497) becomes the box's z; its face (+z) looks down -y.
    root.append(ET.fromstring("<Transformations><Scaling id='1'>12 12 12</Scaling><Rotation id='1'>90 1 0 0"
                              "</Rotation><Translation id='1'>0 0 -0.683</Translation></Transformations>"))
    objects.append(ET.fromstring(f"<Mesh id='100'><Material>100</Material><Faces plyFile='{igea.resolve()}'/>"
                                 "<Transformations>s1 r1 t1</Transformations></Mesh>"))
    out = out_dir / f"igea_box_{kind}.xml"
    ET.ElementTree(root).write(out)
    return out


def absolute_ply_files(root, scene_dir):
    """Names every `plyFile` of the METU scene `root` by its full path (relative ones are relative to
    scene_dir), for a copy of the scene written elsewhere."""
    for el in root.iter():
        if el.get("plyFile"):
            el.set("plyFile", str((Path(scene_dir) / el.get("plyFile").strip()).resolve()))


def square_frame(light):
    """(centre, side axis t, side axis u, unit normal, half side) of an AreaLight: its sides along Arbor's
    orthonormal basis of its normal (math::orthonormal_basis, Duff et al. 2017), t x u = normal."""
    pos, n = np.array(child_floats(light, "Position")), np.array(child_floats(light, "Normal"))
    n = n / np.linalg.norm(n)
    sign = math.copysign(1.0, n[2])
    a = -1.0 / (sign + n[2])
    b = n[0] * n[1] * a
    t, u = np.array([1 + sign * n[0] ** 2 * a, sign * b, -sign * n[0]]), np.array([b, sign + n[1] ** 2 * a, -n[1]])
    return pos, t, u, n, child_floats(light, "Size")[0] / 2


def veach_ajar(out_dir):
    """Writes `veach_ajar_untextured.xml` into out_dir and returns its path: Veach's door scene
    (`ceng795-2022/hw6/veach-ajar/inputs/scene.xml` from $ARBOR_SCENES, 21 objects, 382,624 triangles in
    all), camera 2, its PLY files referenced by their absolute paths, as both renderers render it: each
    textured object's colour is its texture's mean (an image's 8-bit texels raised to 2.2, as Arbor
    reads them; a checkerboard's two colours averaged), and the Phong lobes and the pots' absorption are
    dropped. The notes say so."""
    scenes = Path(os.environ.get("ARBOR_SCENES", "../shared/scenes"))
    source = scenes / "ceng795-2022/hw6/veach-ajar/inputs/scene.xml"
    if not source.is_file():
        raise Unsupported(f"{source} is absent (set ARBOR_SCENES)")
    root = ET.parse(source).getroot()
    cameras = root.find("Cameras")
    for cam in cameras.findall("Camera"):
        if cam.get("id").strip() != "2":
            cameras.remove(cam)
    textures = root.find("Textures")
    images = {i.get("id").strip(): source.parent / i.text.strip() for i in textures.findall("Images/Image")}
    means = {}
    for t in textures.findall("TextureMap"):
        if (t.get("type") or "").strip() == "image":
            texels = read_bitmap(images[t.findtext("ImageId").strip()])
            means[t.get("id").strip()] = np.mean((texels / 255.0) ** 2.2, axis=(0, 1))
        else:
            means[t.get("id").strip()] = (np.array(child_floats(t, "BlackColor")) +
                                          np.array(child_floats(t, "WhiteColor"))) / 2
    root.remove(textures)
    materials = root.find("Materials")
    for m in materials.findall("Material"):
        m.find("SpecularReflectance").text = "0 0 0"
        if m.find("AbsorptionCoefficient") is not None:
            m.find("AbsorptionCoefficient").text = "0 0 0"
    by_id = {m.get("id").strip(): m for m in materials.findall("Material")}
    for obj in root.find("Objects"):
        tex = obj.find("Textures")
        if tex is None:
            continue
        obj.remove(tex)
        # A material of its own: the texture's mean in place of the colour it replaced.
        own = ET.fromstring(ET.tostring(by_id[obj.findtext("Material").strip()]))
        own.set("id", str(100 + len(materials)))
        own.find("DiffuseReflectance").text = " ".join(f"{c:.6f}" for c in means[tex.text.strip()])
        materials.append(own)
        obj.find("Material").text = own.get("id")
    # The square light as geometry in both renderers: Mitsuba's emitters are surfaces, which rays meet and
    # which shadow what lies behind them, and Arbor's square is not. Two one-sided quads back to back (the
    # square lights both its sides), the back one a hair behind.
    lights = root.find("Lights")
    corners, faces = [], []
    for square in lights.findall("AreaLight"):
        lights.remove(square)
        centre, t, u, n, half = square_frame(square)
        for side, c in ((1, centre), (-1, centre - 1e-4 * half * n)):
            base = len(corners)
            corners += [c - half * t - half * u, c + half * t - half * u, c + half * t + half * u, c - half * t + half * u]
            tris = [(0, 1, 2), (0, 2, 3)] if side == 1 else [(0, 2, 1), (0, 3, 2)]
            faces.append((square.findtext("Radiance"), [[base + 1 + i for i in tri] for tri in tris]))
    if corners:
        vertex_data = root.find("VertexData")
        if vertex_data is None:
            vertex_data = ET.SubElement(root, "VertexData")
        offset = len(floats(vertex_data.text)) // 3
        vertex_data.text = (vertex_data.text or "") + "\n" + "\n".join(" ".join(f"{x:.7g}" for x in c) for c in corners)
        black = ET.fromstring(f'<Material id="{100 + len(materials)}"><AmbientReflectance>0 0 0</AmbientReflectance>'
                              "<DiffuseReflectance>0 0 0</DiffuseReflectance><SpecularReflectance>0 0 0"
                              "</SpecularReflectance></Material>")
        materials.append(black)
        for k, (radiance, tris) in enumerate(faces):
            text = " ".join(str(i + offset) for tri in tris for i in tri)
            root.find("Objects").append(ET.fromstring(
                f"<LightMesh id='{100 + k}'><Material>{black.get('id')}</Material><Radiance>{radiance}</Radiance>"
                f"<Faces>{text}</Faces></LightMesh>"))
    absolute_ply_files(root, source.parent)
    out = out_dir / "veach_ajar_untextured.xml"
    ET.ElementTree(root).write(out)
    return out


VEACH_NOTES = ["veach-ajar: textures replaced by their mean colours, Phong lobes (SpecularReflectance) and the "
               "pots' AbsorptionCoefficient dropped, for both renderers (Arbor renders veach_ajar_untextured.xml)"]


# ---------------------------------------------------------------------------------------------
# Rendering


def load_scene(path, camera_id, spp, max_depth, sampler="independent", roulette=False):
    with tempfile.TemporaryDirectory() as tmp:
        desc, cam, depth, notes = metu_to_mitsuba(path, camera_id, spp, max_depth, Path(tmp), sampler, roulette)
        return mi.load_dict(desc), cam, depth, notes


def render_mitsuba(variant, path, camera_id, spp, threads, max_depth, seed=0, sampler="independent", roulette=False):
    """(image, seconds of mi.render) in `variant`; the LLVM variant renders once first to compile."""
    mi.set_variant(variant)
    dr.set_thread_count(threads)
    scene, _, _, _ = load_scene(path, camera_id, spp, max_depth, sampler, roulette)
    runs = 2 if variant.startswith("llvm") else 1
    for _ in range(runs):
        start = time.perf_counter()
        img = mi.render(scene, spp=spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        seconds = time.perf_counter() - start
    return np.array(img)[..., :3], seconds


def cap_isa(isa):
    """Caps Mitsuba's LLVM kernels at `isa` and returns the environment of Arbor's renders (ARBOR_MAX_ISA).
    avx2: Dr.Jit's target stays this processor, with every AVX-512 (and AMX, AVX10) feature turned off,
    at 8 lanes: this processor as an AVX2-only one. (Targeting `haswell` instead made Mitsuba 1.5x slower
    again on a Sapphire Rapids: that measures another processor's tuning, not the instruction set.)
    Dr.Jit has no Python call for its target, so its C++ one is called by its mangled name; Embree, inside
    libmitsuba, keeps the instruction set it detects (Mitsuba's device reads no configuration to cap it)."""
    import ctypes
    env = dict(os.environ)
    if isa == "native":
        env.pop("ARBOR_MAX_ISA", None)
        return env
    core = ctypes.CDLL(os.path.join(os.path.dirname(dr.__file__), "libdrjit-core.so"))
    core._Z19jit_llvm_target_cpuv.restype = core._Z24jit_llvm_target_featuresv.restype = ctypes.c_char_p
    mi.set_variant(REF_VARIANT)
    dr.eval(dr.llvm.Float(1.0))  # the LLVM backend is set up: the target below is not replaced
    cpu, features = core._Z19jit_llvm_target_cpuv(), core._Z24jit_llvm_target_featuresv().split(b",")
    wide = (b"+avx512", b"+amx", b"+avx10")
    features = [b"-" + f[1:] if f.startswith(wide) else f for f in features]
    core._Z19jit_llvm_set_targetPKcS0_j(cpu, b",".join(features), 8)
    width = core._Z21jit_llvm_vector_widthv()
    if width != 8:
        sys.exit(f"cannot cap Dr.Jit at AVX2: its vector width is {width} after setting 8")
    print(f"Dr.Jit's target: {cpu.decode()} without AVX-512, 8 lanes; Arbor: ARBOR_MAX_ISA={isa}", flush=True)
    env["ARBOR_MAX_ISA"] = isa
    return env


def arbor_missing(arbor, integrator, path_options):
    """Why Arbor cannot be run as asked, or None."""
    if not Path(arbor).exists():
        return f"{arbor} does not exist (cargo build --release -p arbor-cli)"
    help_text = subprocess.run([arbor, "render", "--help"], capture_output=True, text=True).stdout
    if integrator and "--integrator" not in help_text:
        return f"`{arbor} render --help` has no --integrator option (no path tracer yet)"
    if path_options and "--path-options" not in help_text:
        return f"`{arbor} render --help` has no --path-options option (pass --arbor-path-options '')"
    if "--roulette" not in help_text:
        return f"`{arbor} render --help` has no --roulette option (a build before Arbor had two roulettes)"
    return None


def render_arbor(arbor, integrator, path_options, path, camera_id, spp, threads, out, seed=0, sampler=None,
                 env=None):
    """(image, seconds of rendering from Arbor's `--stats-json`), or None with the reason printed; in
    environment `env` (--isa), whose kernel cap the stats must show."""
    stats = Path(str(out) + ".stats.json")
    # The unbiased roulette for a camera with one (a camera's RussianRoulette is otherwise the course's).
    cmd = [arbor, "render", str(path), "--camera", camera_id, "--spp", str(spp), "--threads", str(threads),
           "--seed", str(seed), "-o", str(out), "--no-warnings", "--stats-json", str(stats), "--roulette", "unbiased"]
    if integrator:
        cmd += ["--integrator", integrator]
    if integrator and path_options:
        cmd += ["--path-options", path_options]
    if sampler:
        cmd += ["--sampler", sampler]
    run = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if run.returncode != 0 or not stats.is_file():
        print(f"  Arbor failed (exit {run.returncode}): {' '.join(cmd)}\n    " +
              (run.stderr.strip() or run.stdout.strip()).replace("\n", "\n    "))
        return None
    image = json.loads(stats.read_text())["images"][0]
    cap = (env or {}).get("ARBOR_MAX_ISA")
    if cap and image.get("kernel") != cap:
        # No kernel field: a build from before the cap. Another kernel: this processor lacks the capped one.
        why = "a build before the cap" if image.get("kernel") is None else "this processor lacks it"
        sys.exit(f"Arbor ran kernel {image.get('kernel')} under ARBOR_MAX_ISA={cap} ({why}): the comparison "
                 "would not be of that instruction set")
    render_ms = image["render_ms"]
    return read_bitmap(out), render_ms / 1e3  # Arbor's EXR holds radiance in the scene's units


def bitmap_io(io):
    """Runs `io` (a Mitsuba Bitmap read or write) on at least 2 Dr.Jit threads: with `dr.set_thread_count(1)`
    Bitmap's EXR reader and writer never return (Mitsuba 3.9.1, Dr.Jit 1.5.0), which hung `--threads 1`."""
    threads = dr.thread_count()
    dr.set_thread_count(max(threads, 2))
    try:
        return io()
    finally:
        dr.set_thread_count(threads)


def read_bitmap(path):
    """An image file Mitsuba's Bitmap reads (EXR, PNG, JPEG) as float64 RGB, as stored (8-bit files: 0-255)."""
    mi.set_variant(REF_VARIANT)
    return bitmap_io(lambda: np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3])


def write_exr(path, img):
    mi.set_variant(REF_VARIANT)
    bitmap_io(lambda: mi.Bitmap(np.ascontiguousarray(img, dtype=np.float32)).write(str(path)))


def rmse(a, b):
    return float(np.sqrt(np.mean((np.asarray(a, np.float64) - b) ** 2))) if b is not None else None


def mean_relative_difference(a, b, block=1):
    """Mean |a/mean(a) - b/mean(b)| over block x block pixel averages: the images in relative radiance."""
    h, w = (a.shape[0] // block) * block, (a.shape[1] // block) * block
    a, b = (x[:h, :w].reshape(h // block, block, w // block, block, 3).mean(axis=(1, 3)) for x in (a, b))
    return float(np.mean(np.abs(a / a.mean() - b / b.mean())))


# ---------------------------------------------------------------------------------------------
# The comparison


def arbor_scene(path, cache):
    """The scene Arbor renders: `path` itself, or, where a `dielectric` or `mirror` material also has a
    SpecularReflectance (a Phong lobe, which Mitsuba's `dielectric` and `conductor` have no counterpart
    for and the translation drops), a copy in `cache` without that lobe, so that both renderers render
    the same scene (the hw6 glass has one: SpecularReflectance 0.3). ([path], notes)."""
    tree = ET.parse(path)
    dropped = [m for m in tree.getroot().findall("Materials/Material")
               if (m.get("type") or "").strip() in ("dielectric", "mirror")
               and any(child_floats(m, "SpecularReflectance", [0.0]))]
    if not dropped:
        return path, []
    for m in dropped:
        m.find("SpecularReflectance").text = "0 0 0"
    absolute_ply_files(tree.getroot(), Path(path).parent)
    copy = Path(cache) / f"{Path(path).stem}_without_lobes.xml"
    tree.write(copy)
    ids = ", ".join(m.get("id") for m in dropped)
    return copy, [f"material {ids}: its SpecularReflectance (a Phong lobe beside the specular "
                  f"surface) dropped on both sides: Mitsuba has no counterpart, Arbor renders {copy.name}"]


def references(args, path, camera_id, tag, arbor_ok):
    """High-spp images {renderer: image or None}, rendered once and cached in --cache."""
    refs = {}
    mitsuba_file = args.cache / f"{tag}_mitsuba_{args.ref_spp}spp.exr"
    if not mitsuba_file.exists():
        print(f"  rendering the Mitsuba reference ({args.ref_spp} spp) ...", flush=True)
        img, _ = render_mitsuba(REF_VARIANT, path, camera_id, args.ref_spp, max(args.threads), args.max_depth, seed=1,
                                roulette=args.roulette)
        write_exr(mitsuba_file, img)
    refs["Mitsuba"] = read_bitmap(mitsuba_file)
    # "radiance": Arbor's EXRs hold radiance in the scene's units (older caches held it times 1/255).
    arbor_file = args.cache / f"{tag}_arbor_{args.arbor_path_options or 'scene'}_{args.ref_spp}spp_radiance.exr"
    refs["Arbor"] = None
    if arbor_ok and not arbor_file.exists():
        print(f"  rendering the Arbor reference ({args.ref_spp} spp) ...", flush=True)
        render_arbor(args.arbor, args.arbor_integrator, args.arbor_path_options, args.arbor_path, camera_id,
                     args.ref_spp, max(args.threads), arbor_file, seed=1)
    if arbor_ok and arbor_file.exists():
        refs["Arbor"] = read_bitmap(arbor_file)
    return refs


def compare_scene(args, spec, arbor_ok):
    """Rows of the table for one SCENE[:CAMERA] argument."""
    path, _, camera_id = spec.partition(":")
    generated = []
    try:
        if path == "igea-box":
            path, camera_id = igea_box(camera_id, args.cache), "1"
        elif path == "veach-ajar":
            path, camera_id, generated = veach_ajar(args.cache), "2", VEACH_NOTES
    except Unsupported as e:
        print(f"{spec}\n  skipped: {e}")
        return []
    path = Path(path)
    print(f"{path.name}{':' + camera_id if camera_id else ''}", flush=True)
    mi.set_variant(REF_VARIANT)
    try:
        args.roulette = arbor_roulette(path, camera_id or None, args)
        _, cam, depth, notes = load_scene(path, camera_id or None, args.spp, args.max_depth, roulette=args.roulette)
    except Unsupported as e:
        print(f"  skipped: {e}")
        return []
    args.arbor_path, dropped = arbor_scene(path, args.cache)
    for note in generated + notes + dropped:
        print(f"  note: {note}")
    camera_id = cam["id"]
    tag = f"{path.stem}_cam{camera_id}_d{depth}{'_rr' if args.roulette else ''}{'_nolobes' if dropped else ''}"
    roulette = ", Russian roulette (Arbor's unbiased one, Mitsuba's)" if args.roulette else ""
    print(f"  camera {camera_id}, {cam['width']}x{cam['height']}, Mitsuba max_depth {depth}{roulette}", flush=True)
    refs = references(args, path, camera_id, tag, arbor_ok)
    official = path.parent.parent / "outputs" / cam["image_name"]
    if official.exists():
        ref, off = refs["Mitsuba"], read_bitmap(official)
        print(f"  Mitsuba {args.ref_spp} spp vs official {official.name}: mean ratio {ref.mean() / off.mean():.4f}, "
              f"mean |relative difference| {mean_relative_difference(ref, off):.4f} per pixel, "
              f"{mean_relative_difference(ref, off, 16):.4f} in 16x16 blocks")

    samples = cam["width"] * cam["height"] * args.spp
    rows = []
    sampler = args.mitsuba_sampler
    renderers = [(v if sampler == "independent" else f"{v} ({sampler})",
                  lambda t, v=v: render_mitsuba(v, path, camera_id, args.spp, t, args.max_depth, sampler=sampler,
                                                roulette=args.roulette))
                 for v in args.variants]
    if arbor_ok:
        out = args.cache / f"{tag}_arbor_run.exr"
        name = "Arbor" if args.arbor_sampler is None else f"Arbor ({args.arbor_sampler})"
        renderers.append((name, lambda t: render_arbor(args.arbor, args.arbor_integrator, args.arbor_path_options,
                                                       args.arbor_path, camera_id, args.spp, t, out,
                                                       sampler=args.arbor_sampler, env=args.env)))
    for name, render in renderers:
        name_isa = name if args.isa == "native" else f"{name} [{args.isa}]"
        for threads in args.threads:
            result = render(threads)
            if result is None:
                continue
            img, seconds = result
            row = {"scene": f"{path.stem}:{camera_id}", "renderer": name_isa, "threads": threads,
                   "load": os.getloadavg()[0], "seconds": seconds, "samples_per_s": samples / seconds,
                   "rmse_mitsuba": rmse(img, refs["Mitsuba"]), "rmse_arbor": rmse(img, refs["Arbor"])}
            print(f"  {name_isa:12} {threads} threads: {seconds:7.2f} s  {row['samples_per_s'] / 1e6:6.2f} M samples/s  "
                  f"RMSE vs Mitsuba ref {fmt(row['rmse_mitsuba'])}  vs Arbor ref {fmt(row['rmse_arbor'])}  "
                  f"load {row['load']:.1f}", flush=True)
            rows.append(row)
    return rows


def fmt(x):
    return "n/a" if x is None else f"{x:.4f}"


def markdown(rows, args):
    lines = [f"| scene:camera | renderer | threads | render s | M samples/s | RMSE vs Mitsuba {args.ref_spp} spp "
             f"| RMSE vs Arbor {args.ref_spp} spp | load |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['renderer']} | {r['threads']} | {r['seconds']:.2f} | "
                     f"{r['samples_per_s'] / 1e6:.2f} | {fmt(r['rmse_mitsuba'])} | {fmt(r['rmse_arbor'])} | {r['load']:.1f} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="+", metavar="SCENE.xml[:CAMERA_ID]")
    parser.add_argument("--arbor", default="target/release/arbor", help="the arbor binary")
    parser.add_argument("--arbor-integrator", default="path",
                        help="value of arbor's --integrator; empty: leave the flag out (Arbor's default renderer)")
    parser.add_argument("--arbor-path-options", default="mis",
                        help="value of arbor's --path-options (default mis: light and BSDF samples weighted by the "
                             "power heuristic, the estimator of Mitsuba's path integrator); empty: the scene's "
                             "RendererParams")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", default="1,2", help="comma-separated thread counts")
    parser.add_argument("--variants", default="scalar_rgb,llvm_ad_rgb", help="Mitsuba variants to time")
    parser.add_argument("--arbor-sampler", help="Arbor's --sampler for the timed renders (its default when unset); "
                                                "references use Arbor's default")
    parser.add_argument("--mitsuba-sampler", default="independent",
                        help="Mitsuba's sampler for the timed renders (independent, its default; stratified, "
                             "multijitter and ldsampler stratify every dimension); references use independent")
    parser.add_argument("--ref-spp", type=int, default=1024, help="samples per pixel of the reference renders")
    parser.add_argument("--cache", type=Path, default=Path("target/mitsuba-compare"), help="folder of references")
    parser.add_argument("--max-depth", type=int, help="Mitsuba's max_depth instead of MaxRecursionDepth + 2 (Mitsuba only)")
    parser.add_argument("--isa", choices=["native", "avx2"], default="native",
                        help="avx2: both renderers' vectorised code capped at AVX2 on an AVX-512 processor (Arbor's "
                             "kernel by ARBOR_MAX_ISA; Mitsuba's LLVM kernels by Dr.Jit's target, this processor "
                             "without AVX-512 at 8 lanes; Embree keeps what it detects)")
    args = parser.parse_args()
    args.env = cap_isa(args.isa)
    args.threads = [int(t) for t in args.threads.split(",")]
    args.variants = args.variants.split(",")
    args.cache.mkdir(parents=True, exist_ok=True)

    missing = arbor_missing(args.arbor, args.arbor_integrator, args.arbor_path_options)
    if missing:
        print(f"ARBOR LEFT OUT: {missing}; only Mitsuba's side is measured.", flush=True)
    arbor_ok = missing is None
    rows = [row for spec in args.scenes for row in compare_scene(args, spec, arbor_ok)]
    print()
    print(markdown(rows, args))
    return 0 if rows else 1


if __name__ == "__main__":
    sys.exit(main())
