#!/usr/bin/python3
"""Checks what the README's main job (tools/run-demo.sh) wrote against the physics.

Every LUT the demo converted from a simulated capture is compared with the analytic material
the capture was simulated from, evaluated here with NumPy straight from the formulas of
docs/design.md §9 (no project code): for every texel whose outgoing direction lies inside the
measured range (θout ≤ 70°, below the instrument's 75° so the grazing extrapolation is not
involved), the texel's (θd, φd, θin) is mapped back to (ω_in, ω_out) through the specular frame
of docs/design.md §5. The capture carries the simulator's detector noise (about 0.3–0.5 %
median), RGB9E5 rounding (≤ 0.4 %) and the resampling of a coarse φ step, so the median
relative error per material must stay under 3 % and its 90th percentile under 15 %.

It also checks that the atlas, the previews and the pictures the README promises exist and are
images of the requested sizes.

usage: demo_check.py OUT_DIR MATERIALS_DIR MATERIAL...
"""
import json
import os
import struct
import sys

import numpy as np

KTX2_MAGIC = b"\xabKTX 20\xbb\r\n\x1a\n"


def fail(message):
    print("demo_check: " + message)
    sys.exit(1)


def read_ktx2_rgb9e5(path):
    """The 3D RGB9E5 texture of a KTX2 file, as float32 (depth, height, width, 3)."""
    data = open(path, "rb").read()
    if data[:12] != KTX2_MAGIC:
        fail(f"{path}: not a KTX2 file")
    vk_format, _type_size, width, height, depth = struct.unpack_from("<5I", data, 12)
    if vk_format != 123:
        fail(f"{path}: vkFormat {vk_format}, expected 123 (E5B9G9R9_UFLOAT_PACK32)")
    level_offset, level_length = struct.unpack_from("<QQ", data, 80)
    words = np.frombuffer(data, dtype="<u4", count=width * height * depth, offset=level_offset)
    if level_length != words.nbytes:
        fail(f"{path}: level 0 holds {level_length} bytes, expected {words.nbytes}")
    mantissa = np.stack([(words >> s) & 0x1FF for s in (0, 9, 18)], axis=-1).astype(np.float64)
    exponent = ((words >> 27) & 0x1F).astype(np.float64)
    rgb = mantissa * np.exp2(exponent - 15 - 9)[:, None]
    return rgb.reshape(depth, height, width, 3)


def rgb(value):
    return np.broadcast_to(np.asarray(value, dtype=np.float64), (3,))


def analytic(material, wi, wo):
    """f_r (N, 3) of a docs/design.md §9 material for unit directions wi, wo (N, 3)."""
    model = material["model"]
    ci, co = wi[:, 2:3], wo[:, 2:3]
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    ch = np.clip(h[:, 2:3], 1e-12, 1.0)
    tan2_h = (1.0 - ch * ch) / (ch * ch)
    if model == "lambert":
        return np.broadcast_to(rgb(material["rho"]) / np.pi, wi.shape).copy()
    if model == "lafortune":
        kd, ks, n = rgb(material["kd"]), rgb(material["ks"]), rgb(material["n"])
        r = wi * np.array([-1.0, -1.0, 1.0])
        c = np.maximum(np.sum(wo * r, axis=1, keepdims=True), 0.0)
        return kd / np.pi + ks * (n + 2) / (2 * np.pi) * c ** n
    if model == "blinn-phong":
        kd, ks, n = rgb(material["kd"]), rgb(material["ks"]), rgb(material["n"])
        return kd / np.pi + ks * (n + 8) / (8 * np.pi) * ch ** n
    if model == "ward":
        rd, rs, a = rgb(material["rho_d"]), rgb(material["rho_s"]), rgb(material["alpha"])
        return rd / np.pi + rs * np.exp(-tan2_h / a ** 2) / (4 * np.pi * a ** 2 * np.sqrt(ci * co))
    if model == "ggx":
        kd, f0, a = rgb(material["kd"]), rgb(material["f0"]), rgb(material["alpha"])
        d = a ** 2 / (np.pi * ch ** 4 * (a ** 2 + tan2_h) ** 2)

        def g1(c):
            t2 = (1.0 - c * c) / (c * c)
            return 2.0 / (1.0 + np.sqrt(1.0 + a ** 2 * t2))

        vh = np.sum(wo * h, axis=1, keepdims=True)
        f = f0 + (1.0 - f0) * (1.0 - vh) ** 5
        return kd / np.pi + f * g1(ci) * g1(co) * d / (4.0 * ci * co)
    fail(f"model '{model}' has no oracle here")


def check_lut(path, material, theta_in_deg):
    lut = read_ktx2_rgb9e5(path)
    depth, height, width, _ = lut.shape
    if (width, height, depth) != (361, 181, len(theta_in_deg)):
        fail(f"{path}: {width}x{height}x{depth} texels, expected 361x181x{len(theta_in_deg)}")
    errors = []
    for k, theta_in in enumerate(theta_in_deg):
        t = np.radians(theta_in)
        # S(θin) of docs/design.md §5 is symmetric and orthogonal: it is its own inverse.
        s = np.array([[-np.cos(t), 0, -np.sin(t)], [0, -1, 0], [-np.sin(t), 0, np.cos(t)]])
        td, pd = np.meshgrid(np.radians(np.arange(height)), np.radians(np.arange(width)),
                             indexing="ij")
        wd = np.stack([np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)], axis=-1)
        wo = wd.reshape(-1, 3) @ s.T
        inside = wo[:, 2] >= np.cos(np.radians(70.0))
        wo = wo[inside]
        wi = np.broadcast_to(np.array([np.sin(t), 0.0, np.cos(t)]), wo.shape)
        expected = analytic(material, wi, wo)
        got = lut[k].reshape(-1, 3)[inside]
        floor = 0.01 * expected.max()
        errors.append((np.abs(got - expected) / np.maximum(expected, floor)).ravel())
    e = np.concatenate(errors)
    median, p90 = np.median(e), np.percentile(e, 90)
    print(f"demo_check: {os.path.basename(path)}: median relative error {median:.4f}, "
          f"90th percentile {p90:.4f} over {e.size} values")
    if not (median < 0.03 and p90 < 0.15):
        fail(f"{path}: median {median:.4f} (limit 0.03) or 90th percentile {p90:.4f} "
             "(limit 0.15) too far from the analytic material")


def check_not_blank(path, name):
    """Something to look at: at least 5 % of the picture differs by more than 10 of 255 levels
    from its most common colour (the background), and the sphere of the preview, framed at
    90 % of the height around the centre, differs from the corners."""
    import OpenImageIO as oiio
    pixels = oiio.ImageBuf(path).get_pixels(oiio.UINT8)
    if pixels is None or pixels.size == 0:
        fail(f"{name}: cannot be read as an image")
    rgb = pixels[:, :, :3].astype(int).reshape(-1, 3)
    colours, counts = np.unique(rgb, axis=0, return_counts=True)
    background = colours[np.argmax(counts)]
    differing = np.mean(np.max(np.abs(rgb - background), axis=1) > 10)
    if differing < 0.05:
        fail(f"{name}: only {100 * differing:.1f} % of the picture differs from its background")
    if name.startswith("previews/"):
        h, w = pixels.shape[:2]
        centre = pixels[h // 2 - h // 8:h // 2 + h // 8, w // 2 - w // 8:w // 2 + w // 8, :3]
        corner = pixels[:h // 16, :w // 16, :3]
        if abs(float(centre.mean()) - float(corner.mean())) < 5:
            fail(f"{name}: the sphere cannot be told from the background")


def png_size(path):
    data = open(path, "rb").read(24)
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path}: not a PNG")
    return struct.unpack(">II", data[16:24])


def main():
    if len(sys.argv) < 4:
        fail("usage: demo_check.py OUT_DIR MATERIALS_DIR MATERIAL...")
    out, materials_dir, names = sys.argv[1], sys.argv[2], sys.argv[3:]
    for name in names:
        material = json.load(open(os.path.join(materials_dir, name + ".json")))
        sidecar = json.load(open(os.path.join(out, "luts", name + ".json")))
        check_lut(os.path.join(out, "luts", name + ".ktx2"), material, sidecar["theta_in_deg"])
    manifest = json.load(open(os.path.join(out, "atlas", "library.json")))
    listed = json.dumps(manifest)
    for name in names:
        if name not in listed:
            fail(f"atlas manifest does not name '{name}'")
    for picture, size in [("previews/gold.png", (384, 384)),
                          ("pictures/gold-lobe.png", (960, 720)),
                          ("pictures/gold-slices.png", (960, 600))]:
        got = png_size(os.path.join(out, picture))
        if tuple(got) != size:
            fail(f"{picture}: {got[0]}x{got[1]}, expected {size[0]}x{size[1]}")
        check_not_blank(os.path.join(out, picture), picture)
    print(f"demo_check: {len(names)} LUTs, the atlas and the pictures agree with the physics")


if __name__ == "__main__":
    main()
