#!/usr/bin/env python3
"""Writes the project's own example scenes and meshes (nothing here is copied from elsewhere).

cornell_box.xml   Cornell box with a glass sphere, a copper sphere and a torus mesh (inline), METU XML.
knot.json         a torus knot from meshes/torus_knot.ply on a mirror floor plane, METU 2025 JSON form.
meshes/torus_knot.ply  binary little-endian PLY with vertex normals.
trilinear.xml     a checker image texture on a ground quad running to the horizon, trilinear (mipmapped).
textures/checker.png  8x8 texels of one-texel black and white checks (mean 127.5).

Run: python3 examples/generate.py   (from the repository root)
"""
import json, math, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def torus(R, r, nu, nv, center):
    verts, faces = [], []
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            b = 2 * math.pi * j / nv
            x = (R + r * math.cos(b)) * math.cos(a)
            z = (R + r * math.cos(b)) * math.sin(a)
            y = r * math.sin(b)
            verts.append((center[0] + x, center[1] + y, center[2] + z))
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            faces += [(a, d, c), (a, c, b)]
    return verts, faces


def cornell_box():
    tv, tf = torus(2.2, 0.8, 24, 12, (0.0, -9.2, 3.5))
    walls = [(-10, -10, 10), (10, -10, 10), (10, 10, 10), (-10, 10, 10),
             (-10, -10, -10), (10, -10, -10), (10, 10, -10), (-10, 10, -10),
             (-4.5, -5.5, -3.5), (4.5, -6.0, -4.0)]
    verts = walls + tv
    off = len(walls)
    fmt = lambda v: " ".join("%g" % round(c, 5) for c in v)
    torus_faces = "\n".join("                %d %d %d" % tuple(i + off + 1 for i in f) for f in tf)
    return f"""<!-- Arbor's example Cornell box: glass sphere, copper sphere and a torus mesh. Written for
     this project by examples/generate.py; units and conventions of the METU CENG 795 format. -->
<Scene>
    <MaxRecursionDepth>6</MaxRecursionDepth>
    <BackgroundColor>0 0 0</BackgroundColor>
    <ShadowRayEpsilon>1e-3</ShadowRayEpsilon>
    <Cameras>
        <Camera id="1">
            <Position>0 0 20</Position>
            <Gaze>0 0 -1</Gaze>
            <Up>0 1 0</Up>
            <NearPlane>-10 10 -10 10</NearPlane>
            <NearDistance>10</NearDistance>
            <ImageResolution>400 400</ImageResolution>
            <NumSamples>4</NumSamples>
            <ImageName>cornell_box.png</ImageName>
        </Camera>
    </Cameras>
    <Lights>
        <AmbientLight>20 20 20</AmbientLight>
        <PointLight id="1">
            <Position>0 8 4</Position>
            <Intensity>250000 250000 250000</Intensity>
        </PointLight>
    </Lights>
    <Materials>
        <Material id="1">
            <AmbientReflectance>1 1 1</AmbientReflectance>
            <DiffuseReflectance>0.08 0.08 0.08</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
        </Material>
        <Material id="2">
            <AmbientReflectance>0.9 0.1 0.1</AmbientReflectance>
            <DiffuseReflectance>0.09 0.01 0.01</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
        </Material>
        <Material id="3">
            <AmbientReflectance>0.1 0.7 0.1</AmbientReflectance>
            <DiffuseReflectance>0.01 0.07 0.01</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
        </Material>
        <Material id="4" type="dielectric">
            <AmbientReflectance>0 0 0</AmbientReflectance>
            <DiffuseReflectance>0 0 0</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
            <AbsorptionCoefficient>0.02 0.01 0.04</AbsorptionCoefficient>
            <RefractionIndex>1.5</RefractionIndex>
        </Material>
        <Material id="5" type="conductor">
            <AmbientReflectance>0 0 0</AmbientReflectance>
            <DiffuseReflectance>0 0 0</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
            <MirrorReflectance>0.95 0.64 0.54</MirrorReflectance>
            <RefractionIndex>0.27</RefractionIndex>
            <AbsorptionIndex>3.41</AbsorptionIndex>
        </Material>
        <Material id="6">
            <AmbientReflectance>0.3 0.3 1</AmbientReflectance>
            <DiffuseReflectance>0.03 0.03 0.1</DiffuseReflectance>
            <SpecularReflectance>1 1 1</SpecularReflectance>
            <PhongExponent>50</PhongExponent>
        </Material>
    </Materials>
    <VertexData>
{chr(10).join("        " + fmt(v) for v in verts)}
    </VertexData>
    <Objects>
        <Mesh id="1">
            <Material>1</Material>
            <Faces>
                1 2 6
                6 5 1
                5 6 7
                7 8 5
                7 3 4
                4 8 7
            </Faces>
        </Mesh>
        <Mesh id="2">
            <Material>2</Material>
            <Faces>
                8 4 1
                8 1 5
            </Faces>
        </Mesh>
        <Mesh id="3">
            <Material>3</Material>
            <Faces>
                2 3 7
                2 7 6
            </Faces>
        </Mesh>
        <Mesh id="4" shadingMode="smooth">
            <Material>6</Material>
            <Faces>
{torus_faces}
            </Faces>
        </Mesh>
        <Sphere id="1">
            <Material>4</Material>
            <Center>9</Center>
            <Radius>3.5</Radius>
        </Sphere>
        <Sphere id="2">
            <Material>5</Material>
            <Center>10</Center>
            <Radius>3.5</Radius>
        </Sphere>
    </Objects>
</Scene>
"""


def torus_knot(p=2, q=3, nu=256, nv=16, R=2.0, r=0.45, tube=0.35):
    def curve(t):
        rr = R + r * 3 * math.cos(q * t) * 0.5
        return (rr * math.cos(p * t), r * 3 * math.sin(q * t) * 0.5, rr * math.sin(p * t))
    verts, norms, faces = [], [], []
    for i in range(nu):
        t = 2 * math.pi * i / nu
        c = curve(t)
        c2 = curve(t + 1e-3)
        tan = [c2[k] - c[k] for k in range(3)]
        l = math.sqrt(sum(x * x for x in tan)); tan = [x / l for x in tan]
        up = (0.0, 1.0, 0.0)
        n1 = [tan[1] * up[2] - tan[2] * up[1], tan[2] * up[0] - tan[0] * up[2], tan[0] * up[1] - tan[1] * up[0]]
        l = math.sqrt(sum(x * x for x in n1)); n1 = [x / l for x in n1]
        n2 = [tan[1] * n1[2] - tan[2] * n1[1], tan[2] * n1[0] - tan[0] * n1[2], tan[0] * n1[1] - tan[1] * n1[0]]
        for j in range(nv):
            b = 2 * math.pi * j / nv
            n = [math.cos(b) * n1[k] + math.sin(b) * n2[k] for k in range(3)]
            verts.append(tuple(c[k] + tube * n[k] for k in range(3)))
            norms.append(tuple(n))
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            faces += [(a, c, b), (a, d, c)]  # counter-clockwise around the outward normals
    return verts, norms, faces


def write_ply(path, verts, norms, faces):
    header = ("ply\nformat binary_little_endian 1.0\ncomment written by arbor examples/generate.py\n"
              f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        for v, n in zip(verts, norms):
            f.write(struct.pack("<6f", *v, *n))
        for t in faces:
            f.write(struct.pack("<B3i", 3, *t))


def knot_scene():
    s = lambda v: " ".join("%g" % x for x in v)
    return {"Scene": {
        "MaxRecursionDepth": "3",
        "BackgroundColor": "20 30 50",
        "ShadowRayEpsilon": "1e-3",
        "Cameras": {"Camera": {"_id": "1", "_type": "lookAt", "Position": "0 3.5 9", "GazePoint": "0 0 0",
                               "Up": "0 1 0", "FovY": "40", "NearDistance": "1",
                               "ImageResolution": "480 320", "NumSamples": "4", "ImageName": "knot.png"}},
        "Lights": {"AmbientLight": "25 25 25",
                   "PointLight": [{"_id": "1", "Position": "4 8 6", "Intensity": "90000 90000 90000"},
                                  {"_id": "2", "Position": "-6 5 2", "Intensity": "30000 30000 40000"}]},
        "Materials": {"Material": [
            {"_id": "1", "AmbientReflectance": "0.8 0.5 0.2", "DiffuseReflectance": "0.8 0.45 0.15",
             "SpecularReflectance": "1 1 1", "PhongExponent": "80"},
            {"_id": "2", "_type": "mirror", "AmbientReflectance": "0.2 0.2 0.2",
             "DiffuseReflectance": "0.3 0.3 0.35", "SpecularReflectance": "0 0 0",
             "MirrorReflectance": "0.4 0.4 0.4"}]},
        "VertexData": {"_data": "0 -1.6 0", "_type": "xyz"},
        "Objects": {
            "Mesh": {"_id": "1", "_shadingMode": "smooth", "Material": "1",
                     "Faces": {"_plyFile": "meshes/torus_knot.ply"}},
            "Plane": {"_id": "1", "Material": "2", "Point": "1", "Normal": "0 1 0"}}}}


def write_png(path, width, height, rgb):
    """8-bit RGB PNG, rows from the top; `rgb` holds width * height (r, g, b) tuples."""
    rows = b"".join(b"\0" + bytes(c for px in rgb[y * width:(y + 1) * width] for c in px) for y in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def checker(n=8):
    return [(255,) * 3 if (x + y) % 2 else (0,) * 3 for y in range(n) for x in range(n)]


def trilinear_scene():
    # replace_all shows texels in radiance units (0-255, Normalizer 1), as the course's scenes do.
    # A ground quad 400 units deep, one texture tile per 4 units: near the horizon a pixel covers many
    # texels, which only a mipmap averages (with one sample per pixel, nearest and bilinear alias).
    return """<!-- Arbor's example of trilinear texture filtering: a checker image on a ground quad running to
     the horizon, one sample per pixel. Written for this project by examples/generate.py. -->
<Scene>
    <MaxRecursionDepth>0</MaxRecursionDepth>
    <BackgroundColor>120 160 220</BackgroundColor>
    <ShadowRayEpsilon>1e-3</ShadowRayEpsilon>
    <Cameras>
        <Camera id="1">
            <Position>0 2 0</Position>
            <Gaze>0 -0.35 -1</Gaze>
            <Up>0 1 0</Up>
            <NearPlane>-1 1 -1 1</NearPlane>
            <NearDistance>1.5</NearDistance>
            <ImageResolution>256 256</ImageResolution>
            <NumSamples>1</NumSamples>
            <ImageName>trilinear.png</ImageName>
        </Camera>
    </Cameras>
    <Lights>
        <AmbientLight>255 255 255</AmbientLight>
    </Lights>
    <Materials>
        <Material id="1">
            <AmbientReflectance>1 1 1</AmbientReflectance>
            <DiffuseReflectance>0 0 0</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
        </Material>
    </Materials>
    <Textures>
        <Images>
            <Image id="1">textures/checker.png</Image>
        </Images>
        <TextureMap id="1" type="image">
            <ImageId>1</ImageId>
            <DecalMode>replace_all</DecalMode>
            <Interpolation>trilinear</Interpolation>
            <Normalizer>1</Normalizer>
        </TextureMap>
    </Textures>
    <VertexData>
        -200 0 5
        200 0 5
        200 0 -400
        -200 0 -400
    </VertexData>
    <TexCoordData>
        -50 1.25
        50 1.25
        50 -100
        -50 -100
    </TexCoordData>
    <Objects>
        <Mesh id="1">
            <Material>1</Material>
            <Textures>1</Textures>
            <Faces>1 2 3 1 3 4</Faces>
        </Mesh>
    </Objects>
</Scene>
"""


if __name__ == "__main__":
    with open(os.path.join(HERE, "cornell_box.xml"), "w") as f:
        f.write(cornell_box())
    v, n, fc = torus_knot()
    write_ply(os.path.join(HERE, "meshes", "torus_knot.ply"), v, n, fc)
    with open(os.path.join(HERE, "knot.json"), "w") as f:
        json.dump(knot_scene(), f, indent=2)
        f.write("\n")
    os.makedirs(os.path.join(HERE, "textures"), exist_ok=True)
    write_png(os.path.join(HERE, "textures", "checker.png"), 8, 8, checker())
    with open(os.path.join(HERE, "trilinear.xml"), "w") as f:
        f.write(trilinear_scene())
