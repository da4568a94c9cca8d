"""Engine hand-off files checked where a Debian tool can check them (ctest: engine_handoff_checks).

  - The Unreal RGBA16F volume DDS, parsed here from Microsoft's DDS_HEADER / DDS_HEADER_DXT10
    layout (OpenImageIO 2.4 reads no DX10 DDS): DXGI 10, 3D, depth K, one mip; every half
    equals the RGB9E5 decode (EXT_texture_shared_exponent, written here) of the KTX2 texel,
    alpha 1. The Godot DDS is DXGI 67 with the KTX2's own payload bytes.
  - The Unity ScriptedImporter compiled by mcs against stub UnityEngine/UnityEditor types and
    run under mono on the shipped .brdf3d, once on the E5B9G9R9 path and once on the RGBAHalf
    fallback: dimensions, format, clamp, filtering, no mips, and the texels it uploads.
  - The Unreal editor script byte-compiled (py_compile) and run against a stub `unreal`
    module: both import routes ask for sRGB off, TC_HDR, no mips, clamp, tiles 361 × 181.
  - The Godot .import file: importer 3d_texture, 2 × 2 slices, no mipmaps.
  - The IBL pack texture NAME_ibl.dds (of a LUT and of a two-material atlas): DXGI 10, 2D, one
    mip, 64 × cells; every half is numpy's float16 of the manifest's "ibl" numbers (texel i:
    specular_rgb, alpha_eq at mu_i), identical in every engine folder; the diffuse constants
    diffuse_quadratic_rgb are numpy's least-squares quadratic in 1 - mu of diffuse_rgb, and
    with them D_fit(mu_i) + specular_rgb = albedo_rgb.
  - `brdf fit` output passed with --engine-fits is the manifest's fallback material, as written.
  - The BC6H hand-off (`--engine all --compress bc6h`): the Unreal and Godot DDS are DXGI 95
    volumes of 364 × 184 × K (the padded size) holding the KTX2's blocks; Unity's importer
    uploads those blocks as RGB_BC6H_UFloat 364 × 184 × K; the 2D forms (Unity
    NAME_flipbook.exr, Unreal NAME_tiles.exr, Godot NAME_slices.exr) are 364 × 184 tiles whose
    every texel is the numpy BC6H decode (tests/python/bc6h_oracle.py) of the blocks, padding
    included; the import settings keep the block format under each engine's documented names
    (Unity TextureImporterSettings / TextureImporterPlatformSettings through the stubs: Texture3D,
    flipbook columns × rows, sRGB off, no mipmaps, no NPOT scale, clamp, Standalone override
    BC6H, no crunch; Unreal TC_HDR_COMPRESSED, no mips, tiles 364 × 184; Godot compress/mode 2
    (VRAM Compressed), high_quality (BC6H), hdr_compression 2, no mipmaps); every shader is
    the *_bc6h one. `--compress compact --engine` is refused; `--max-error` with --engine picks
    BC6H or RGB9E5, never the compact form.
Usage: engine_handoff_checks.py BRDF_TOOL SOURCE_DIR MCS MONO   (Debian /usr/bin/python3)
"""
import configparser
import json
import os
import py_compile
import shutil
import struct
import subprocess
import sys
import tempfile

import numpy as np

from check_support import FAILURES, expect, run

MATERIAL = {"model": "ggx", "kd": [0.3, 0.2, 0.1], "f0": [0.9, 0.6, 0.3], "alpha": 0.2}




def decode_rgb9e5(words):
    w = np.asarray(words, dtype=np.int64)
    scale = np.exp2(((w >> 27) & 31).astype(float) - 24.0)
    return np.stack([(w & 511) * scale, ((w >> 9) & 511) * scale, ((w >> 18) & 511) * scale], -1)


def ktx2_payload(path):
    data = open(path, "rb").read()
    width, height, depth = struct.unpack_from("<3I", data, 20)
    offset, length = struct.unpack_from("<QQ", data, 80)
    return data[offset:offset + length], (depth, height, width)


def parse_dds(path):
    """DDS_HEADER + DDS_HEADER_DXT10 (Microsoft DDS programming guide)."""
    data = open(path, "rb").read()
    assert data[:4] == b"DDS ", f"{path}: magic {data[:4]!r}"
    size, flags, height, width, pitch, depth, mips = struct.unpack_from("<7I", data, 4)
    pf_size, pf_flags, fourcc = struct.unpack_from("<II4s", data, 76)
    caps, caps2 = struct.unpack_from("<II", data, 108)
    dxgi, dimension, misc, array_size, misc2 = struct.unpack_from("<5I", data, 128)
    return dict(size=size, flags=flags, height=height, width=width, pitch=pitch, depth=depth,
                mips=mips, pf_size=pf_size, pf_flags=pf_flags, fourcc=fourcc, caps=caps,
                caps2=caps2, dxgi=dxgi, dimension=dimension, array_size=array_size,
                data=data[148:])


def check_dds(out, name):
    payload, shape = ktx2_payload(os.path.join(out, name + ".ktx2"))
    words = np.frombuffer(payload, dtype="<u4").reshape(shape)
    want = decode_rgb9e5(words)
    d = parse_dds(os.path.join(out, "unreal", name + ".dds"))
    expect(d["size"] == 124 and d["fourcc"] == b"DX10" and d["dxgi"] == 10, f"unreal DDS header {d['fourcc']} dxgi {d['dxgi']}")
    expect(d["dimension"] == 4 and d["array_size"] == 1, "unreal DDS is not a 3D texture")
    expect(d["caps2"] & 0x200000 and d["flags"] & 0x800000, "unreal DDS lacks DDSCAPS2_VOLUME / DDSD_DEPTH")
    expect((d["width"], d["height"], d["depth"], d["mips"]) == (361, 181, 4, 1),
           f"unreal DDS size {d['width']}x{d['height']}x{d['depth']} mips {d['mips']}")
    expect(d["pitch"] == 361 * 8, f"unreal DDS pitch {d['pitch']}")
    halves = np.frombuffer(d["data"], dtype="<f2").reshape(4, 181, 361, 4).astype(np.float64)
    diff = np.abs(halves[..., :3] - want)
    expect(float(diff.max()) == 0.0, f"unreal DDS halves differ from the RGB9E5 decode by {diff.max()}")
    expect(bool(np.all(halves[..., 3] == 1.0)), "unreal DDS alpha is not 1")
    print(f"unreal DDS: DXGI 10 volume 361x181x4, 1 mip; {halves[..., :3].size} half values equal "
          f"the RGB9E5 decode exactly (max |diff| {diff.max()}); peak {want.max():.4g}")
    g = parse_dds(os.path.join(out, "godot", name + ".dds"))
    expect(g["dxgi"] == 67 and g["depth"] == 4 and g["mips"] == 1 and g["data"] == payload,
           "godot DDS is not the RGB9E5 volume with the KTX2's payload")
    print("godot DDS: DXGI 67 volume, 1 mip, payload identical to the KTX2 level 0 image")
    return words, want


def check_ibl_pack(folder, name, engines):
    d = parse_dds(os.path.join(folder, engines[0], name + "_ibl.dds"))
    manifest = json.load(open(os.path.join(folder, engines[0], name + ".manifest.json")))
    ibl = manifest["ibl"]
    cells = ibl["cells"] if manifest["atlas"] else [ibl]
    expect(d["size"] == 124 and d["fourcc"] == b"DX10" and d["dxgi"] == 10 and d["mips"] == 1,
           f"{name}_ibl.dds header {d['fourcc']} dxgi {d['dxgi']} mips {d['mips']}")
    expect(d["dimension"] == 3 and not (d["caps2"] & 0x200000) and not (d["flags"] & 0x800000),
           f"{name}_ibl.dds is not a 2D texture (dimension {d['dimension']})")
    expect((d["width"], d["height"], d["pitch"]) == (64, len(cells), 64 * 8),
           f"{name}_ibl.dds size {d['width']}x{d['height']} pitch {d['pitch']}")
    texels = np.frombuffer(d["data"], dtype="<f2").reshape(len(cells), 64, 4)
    for m, c in enumerate(cells):
        expect(c.get("row", m) == m, f"{name}: cell {m} row {c.get('row')}")
        want = np.zeros((64, 4))
        want[:, :3] = c["specular_rgb"]
        want[:, 3] = c["alpha_eq"]
        got = texels[m]
        same = np.array_equal(got, want.astype(np.float16))
        expect(same, f"{name}_ibl.dds row {m} differs from float16 of the manifest by "
                     f"{np.abs(got.astype(float) - want).max()}")
        # The diffuse constants: numpy's own least-squares quadratic in t = 1 - mu of the
        # manifest's diffuse_rgb, and with them D_fit(mu_i) + S_i = E_i at every texel centre.
        mu = np.asarray(c["mu"])
        t = 1.0 - mu
        diffuse = np.asarray(c["diffuse_rgb"])
        coeffs = np.asarray(c["diffuse_quadratic_rgb"])
        expect(coeffs.shape == (3, 3), f"{name}: diffuse_quadratic_rgb shape {coeffs.shape}")
        basis = np.stack([np.ones_like(t), t, t * t], axis=1)
        lstsq = np.linalg.lstsq(basis, diffuse, rcond=None)[0]
        fit_err = np.abs(lstsq - coeffs).max()
        expect(fit_err <= 1e-5 * max(1.0, np.abs(lstsq).max()),
               f"{name}: diffuse_quadratic_rgb differs from numpy's least squares by {fit_err}")
        albedo = np.asarray(c["albedo_rgb"])
        split = np.abs(basis @ coeffs + np.asarray(c["specular_rgb"]) - albedo)
        expect(split.max() <= 1e-5 * max(1.0, albedo.max()),
               f"{name}: D_fit + S differs from E by {split.max()}")
    data = open(os.path.join(folder, engines[0], name + "_ibl.dds"), "rb").read()
    for e in engines[1:]:
        expect(open(os.path.join(folder, e, name + "_ibl.dds"), "rb").read() == data,
               f"{e}/{name}_ibl.dds differs from {engines[0]}'s")
    print(f"{name}_ibl.dds: DXGI 10 2D 64x{len(cells)}, 1 mip; every half is float16 of the manifest's pack; "
          "diffuse_quadratic_rgb is numpy's least-squares fit, D_fit + S = E")


def check_unity(out, name, mcs, mono, work, words, want):
    unity = os.path.join(out, "unity")
    stubs = os.path.join(os.path.dirname(os.path.abspath(__file__)), "stubs")
    exe = os.path.join(work, "driver.exe")
    run([mcs, "-nologo", "-warnaserror+", "-out:" + exe,
         os.path.join(unity, "Editor", "MeasuredBrdfImporter.cs"),
         os.path.join(stubs, "UnityStubs.cs"), os.path.join(stubs, "ImporterDriver.cs")])
    for mode in ("e5", "half"):
        prefix = os.path.join(work, "unity_" + mode)
        run([mono, exe, os.path.join(unity, name + ".brdf3d"), prefix] + (["half"] if mode == "half" else []))
        info = json.load(open(prefix + ".json"))
        expect(info["errors"] == [], f"unity importer errors: {info['errors']}")
        expect(info["extensions"] == ["brdf3d"] and info["override_extensions"] == ["ktx2"],
               f"unity importer extensions {info['extensions']} / {info['override_extensions']}")
        expect((info["width"], info["height"], info["depth"]) == (361, 181, 4), f"unity size {info}")
        expect(info["format"] == ("E5B9G9R9_UFloatPack32" if mode == "e5" else "R16G16B16A16_SFloat"),
               f"unity format {info['format']}")
        expect(info["wrap"] == "Clamp" and info["filter"] == "Bilinear" and info["aniso"] == 0,
               f"unity sampler {info['wrap']} {info['filter']}")
        expect(info["applied"] and not info["mipmaps_updated"], "unity texture mipmaps updated")
        if mode == "e5":
            got = np.fromfile(prefix + ".bin", dtype="<u4")
            expect(np.array_equal(got, words.reshape(-1)), "unity uploads other words than the KTX2's")
        else:
            got = np.fromfile(prefix + ".bin", dtype="<f4").reshape(-1, 4).astype(np.float64)
            expect(np.array_equal(got[:, :3], want.reshape(-1, 3)) and np.all(got[:, 3] == 1.0),
                   "unity half fallback converts other values than the RGB9E5 decode")
    print("unity importer: compiled by mcs (warnings as errors), run under mono: Texture3D 361x181x4 "
          "E5B9G9R9_UFloatPack32 with the KTX2's words, RGBAHalf fallback with the exact RGB9E5 "
          "decode; clamp, bilinear, no mips")
    # A damaged file is refused with one line naming the byte.
    bad = os.path.join(work, "bad.brdf3d")
    data = bytearray(open(os.path.join(unity, name + ".brdf3d"), "rb").read())
    data[12] = 97
    open(bad, "wb").write(bytes(data))
    run([mono, exe, bad, os.path.join(work, "unity_bad")])
    info = json.load(open(os.path.join(work, "unity_bad.json")))
    expect(len(info["errors"]) == 1 and "byte 12: expected vkFormat 123" in info["errors"][0]
           and "got 97" in info["errors"][0], f"unity importer on a bad vkFormat: {info['errors']}")


def check_unreal(out, work):
    unreal = os.path.join(out, "unreal")
    script = os.path.join(unreal, "import_measured_brdf.py")
    py_compile.compile(script, doraise=True)
    stubs = os.path.join(os.path.dirname(os.path.abspath(__file__)), "stubs")
    for route in ([], ["--tiles"]):
        log = os.path.join(work, "unreal%s.json" % ("_tiles" if route else ""))
        env = dict(os.environ, PYTHONPATH=stubs, UNREAL_STUB_LOG=log)
        run([sys.executable, script] + route, env=env)
        record = json.load(open(log))
        sets = {}
        for r in record:
            if "set" in r:
                sets.setdefault(r["type"], {})[r["set"]] = r["value"]
        imports = [r for r in record if "import" in r]
        if not route:
            expect(len(imports) == 1 and imports[0]["import"].endswith(".dds"), f"unreal imports {imports}")
            vol = sets.get("VolumeTexture", {})
        else:
            expect(len(imports) == 1 and imports[0]["import"].endswith("_tiles.exr"), f"unreal imports {imports}")
            vol = sets.get("VolumeTexture", {})
            expect(vol.get("source2d_tile_size_x") == 361 and vol.get("source2d_tile_size_y") == 181,
                   f"unreal tile size {vol}")
            tex = sets.get("Texture2D", {})
            expect(tex.get("srgb") is False and tex.get("compression_settings") == "TextureCompressionSettings.TC_HDR",
                   f"unreal tiles texture settings {tex}")
        expect(vol.get("srgb") is False, f"unreal sRGB {vol}")
        expect(vol.get("compression_settings") == "TextureCompressionSettings.TC_HDR", f"unreal compression {vol}")
        expect(vol.get("mip_gen_settings") == "TextureMipGenSettings.TMGS_NO_MIPMAPS", f"unreal mips {vol}")
        expect(vol.get("address_mode") == "TextureAddress.TA_CLAMP", f"unreal address {vol}")
    print("unreal script: py_compile ok; against the stub module both routes import (DDS; tiles "
          "361x181 into a Volume Texture) with sRGB off, TC_HDR, no mips, clamp")


def check_godot(out, name):
    cp = configparser.ConfigParser()
    text = open(os.path.join(out, "godot", name + "_slices.exr.import")).read()
    cp.read_string("\n".join(l for l in text.splitlines() if not l.startswith(";")))
    expect(cp["remap"]["importer"] == '"3d_texture"', f"godot importer {cp['remap']['importer']}")
    expect(cp["params"]["slices/horizontal"] == "2" and cp["params"]["slices/vertical"] == "2",
           "godot slices")
    expect(cp["params"]["mipmaps/generate"] == "false", "godot mipmaps")
    import OpenImageIO as oiio  # Debian python3-openimageio
    inp = oiio.ImageInput.open(os.path.join(out, "godot", name + "_slices.exr"))
    expect(inp is not None and (inp.spec().width, inp.spec().height) == (722, 362),
           "godot sliced EXR is not 2 x 2 tiles of 361 x 181")
    if inp:
        inp.close()
    print("godot: .import = 3d_texture, 2 x 2 slices, no mipmaps; sliced EXR 722 x 362 (OpenImageIO)")


def check_fits(tool, mat, work):
    """`brdf fit` results given with --engine-fits land in the manifest as written by brdf fit."""
    fits = os.path.join(work, "fits")
    os.makedirs(fits)
    fit_file = os.path.join(fits, "gold_like.lambert.json")  # the name `--out FITS` would give
    run([tool, "fit", mat, "--model", "lambert", "--out", fit_file, "--quiet"])
    fit = json.load(open(fit_file))
    out = os.path.join(work, "out_fits")
    run([tool, "convert", mat, "--out", out, "--engine", "web", "--engine-fits", fits, "--quiet",
         "--formats", "ktx2"])
    fallback = json.load(open(os.path.join(out, "web", "gold_like.manifest.json")))["fallback_material"]
    models = fallback["models"] if fallback else []
    expect(len(models) == 1 and models[0] == fit, f"--engine-fits: fallback models {models!r:.300}")
    expect(fallback is not None and fallback["gltf"] is None, "--engine-fits: glTF values without an unreal-defaultlit fit")
    print(f"--engine-fits: the brdf fit result (lambert, rmse {fit['fit']['rmse']:.4g}) is the manifest's fallback material as written")


def padded_bc6h_decode(payload, width, height, depth):
    """Every texel of the blocks, padding included: (depth, 4·ceil(h/4), 4·ceil(w/4), 3)."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
    import bc6h_oracle
    bw, bh = (width + 3) // 4, (height + 3) // 4
    halves = np.zeros((depth, 4 * bh, 4 * bw, 3), dtype=np.uint16)
    for z in range(depth):
        for by in range(bh):
            for bx in range(bw):
                at = ((z * bh + by) * bw + bx) * 16
                halves[z, 4 * by:4 * by + 4, 4 * bx:4 * bx + 4] = np.array(
                    bc6h_oracle.decode_block(payload[at:at + 16]), dtype=np.uint16).reshape(4, 4, 3)
    return halves.view(np.float16).astype(np.float64)


def read_exr(path):
    import OpenImageIO as oiio  # Debian python3-openimageio
    inp = oiio.ImageInput.open(path)
    expect(inp is not None, f"{path}: OpenImageIO cannot open it")
    if inp is None:
        return None
    pixels = np.asarray(inp.read_image("float"), dtype=np.float64)
    inp.close()
    return pixels[..., :3]


def check_bc6h(tool, mat, mcs, mono, work):
    out = os.path.join(work, "out_bc6h")
    run([tool, "convert", mat, "--out", out, "--engine", "all", "--compress", "bc6h", "--quiet",
         "--formats", "ktx2,json", "--beyond", "clamp"])
    name = "gold_like"
    data = open(os.path.join(out, name + ".ktx2"), "rb").read()
    vk_format, _, width, height, depth = struct.unpack_from("<5I", data, 12)
    offset, length = struct.unpack_from("<QQ", data, 80)
    payload = data[offset:offset + length]
    expect((vk_format, width, height, depth) == (131, 361, 181, 4), f"BC6H KTX2 header {vk_format} {width}x{height}x{depth}")
    for folder in ("unreal", "godot"):
        d = parse_dds(os.path.join(out, folder, name + ".dds"))
        expect(d["fourcc"] == b"DX10" and d["dxgi"] == 95 and d["dimension"] == 4 and d["mips"] == 1,
               f"{folder} BC6H DDS header {d['fourcc']} dxgi {d['dxgi']} dimension {d['dimension']}")
        expect((d["width"], d["height"], d["depth"]) == (364, 184, 4), f"{folder} BC6H DDS size {d['width']}x{d['height']}x{d['depth']}")
        expect(d["data"] == payload, f"{folder} BC6H DDS holds other bytes than the KTX2's blocks")
    print("BC6H unreal/godot DDS: DXGI 95 volumes 364x184x4, 1 mip, the KTX2's blocks")
    for folder, suffix in (("unity", ".hlsl"), ("unreal", ".ush"), ("godot", ".gdshader"), ("web", ".js")):
        shaders = sorted(f for f in os.listdir(os.path.join(out, folder)) if f.endswith(suffix))
        expect(shaders == [("MeasuredBrdf_bc6h" if folder in ("unity", "unreal") else "measured_brdf_bc6h") + suffix],
               f"BC6H {folder} shaders {shaders}")
    # Unity: the importer on the BC6H .brdf3d.
    exe = os.path.join(work, "driver.exe")  # compiled by check_unity
    prefix = os.path.join(work, "unity_bc6h")
    run([mono, exe, os.path.join(out, "unity", name + ".brdf3d"), prefix])
    info = json.load(open(prefix + ".json"))
    expect(info["errors"] == [] and (info.get("width"), info.get("height"), info.get("depth")) == (364, 184, 4)
           and info.get("format") == "RGB_BC6H_UFloat" and info.get("wrap") == "Clamp"
           and info.get("filter") == "Bilinear" and info.get("applied") and not info.get("mipmaps_updated"),
           f"unity BC6H import {info}")
    expect(open(prefix + ".bin", "rb").read() == payload, "unity uploads other bytes than the KTX2's blocks")
    # The 2D forms: block-aligned tiles of the decoded blocks.
    decoded = padded_bc6h_decode(payload, width, height, depth)
    for folder, file in (("unity", name + "_flipbook.exr"), ("unreal", name + "_tiles.exr"),
                         ("godot", name + "_slices.exr")):
        img = read_exr(os.path.join(out, folder, file))
        if img is None:
            continue
        expect(img.shape == (2 * 184, 2 * 364, 3), f"{folder} {file}: {img.shape}, expected 2 x 2 tiles of 364 x 184")
        if img.shape == (2 * 184, 2 * 364, 3):
            tiles = np.stack([img[(k // 2) * 184:(k // 2 + 1) * 184, (k % 2) * 364:(k % 2 + 1) * 364] for k in range(4)])
            expect(np.array_equal(tiles, decoded), f"{folder} {file}: texels differ from the BC6H decode by "
                   f"{np.abs(tiles - decoded).max()}")
    print("BC6H 2D forms: unity _flipbook.exr, unreal _tiles.exr, godot _slices.exr are 2 x 2 tiles of "
          "364 x 184, every texel (padding included) the numpy decode of the blocks")
    run([mono, exe, "flipbook", "Assets/MeasuredBrdf/" + name + "_flipbook.exr", "728", "368", prefix + "_flipbook"])
    fb = json.load(open(prefix + "_flipbook.json"))
    want = {"errors": [], "textureShape": "Texture3D", "flipbookColumns": 2, "flipbookRows": 2,
            "sRGBTexture": False, "mipmapEnabled": False, "npotScale": "None", "wrapMode": "Clamp",
            "filterMode": "Bilinear", "alphaSource": "None", "textureCompression": "CompressedHQ",
            "crunchedCompression": False,
            "standalone": {"name": "Standalone", "overridden": True, "format": "BC6H",
                           "textureCompression": "Compressed", "crunchedCompression": False,
                           "maxTextureSize": 8192}}
    expect(fb == want, f"unity flipbook import settings {fb}")
    run([mono, exe, "flipbook", "Assets/x_flipbook.exr", "730", "368", prefix + "_odd"])
    odd = json.load(open(prefix + "_odd.json"))
    expect(len(odd["errors"]) == 1 and "730 x 368" in odd["errors"][0] and odd["textureShape"] == "Texture2D",
           f"unity flipbook of a size that is not whole tiles: {odd}")
    print("BC6H unity: importer uploads the blocks as RGB_BC6H_UFloat 364x184x4; the flipbook "
          "postprocessor sets Texture3D 2 x 2, sRGB off, no mips, NPOT None, clamp, bilinear, "
          "CompressedHQ without crunch, Standalone override BC6H")
    # Unreal: TC_HDR_COMPRESSED on both routes, tiles 364 x 184.
    script = os.path.join(out, "unreal", "import_measured_brdf.py")
    stubs = os.path.join(os.path.dirname(os.path.abspath(__file__)), "stubs")
    for route in ([], ["--tiles"]):
        log = os.path.join(work, "unreal_bc6h%s.json" % ("_tiles" if route else ""))
        run([sys.executable, script] + route, env=dict(os.environ, PYTHONPATH=stubs, UNREAL_STUB_LOG=log))
        sets = {}
        for r in json.load(open(log)):
            if "set" in r:
                sets.setdefault(r["type"], {})[r["set"]] = r["value"]
        vol = sets.get("VolumeTexture", {})
        expect(vol.get("srgb") is False and vol.get("compression_settings") == "TextureCompressionSettings.TC_HDR_COMPRESSED"
               and vol.get("mip_gen_settings") == "TextureMipGenSettings.TMGS_NO_MIPMAPS",
               f"unreal BC6H volume settings {vol}")
        if route:
            expect(vol.get("source2d_tile_size_x") == 364 and vol.get("source2d_tile_size_y") == 184,
                   f"unreal BC6H tile size {vol}")
            tex = sets.get("Texture2D", {})
            expect(tex.get("compression_settings") == "TextureCompressionSettings.TC_HDR_COMPRESSED"
                   and tex.get("srgb") is False, f"unreal BC6H tiles texture {tex}")
    print("BC6H unreal script: both routes TC_HDR_COMPRESSED, sRGB off, no mips; tiles 364x184")
    # Godot: VRAM Compressed, high quality (BC6H), HDR always, no mipmaps.
    cp = configparser.ConfigParser()
    text = open(os.path.join(out, "godot", name + "_slices.exr.import")).read()
    cp.read_string("\n".join(l for l in text.splitlines() if not l.startswith(";")))
    params = dict(cp["params"])
    expect(cp["remap"]["importer"] == '"3d_texture"' and params.get("compress/mode") == "2"
           and params.get("compress/high_quality") == "true" and params.get("compress/hdr_compression") == "2"
           and params.get("mipmaps/generate") == "false" and params.get("slices/horizontal") == "2"
           and params.get("slices/vertical") == "2", f"godot BC6H import {params}")
    print("BC6H godot: .import compress/mode 2 (VRAM Compressed), high_quality, hdr_compression 2, "
          "no mipmaps, 2 x 2 slices")
    # --compress compact has no engine kit; --max-error with --engine never picks it.
    bad = subprocess.run([tool, "convert", mat, "--out", os.path.join(work, "compact_bad"),
                          "--engine", "all", "--compress", "compact"], capture_output=True, text=True)
    expect(bad.returncode == 1 and bad.stderr.count("\n") == 1 and "no engine kit samples the compact form" in bad.stderr
           and not os.path.exists(os.path.join(work, "compact_bad", "web")),
           f"--compress compact --engine: exit {bad.returncode}, {bad.stderr!r}")
    for bound, form in (("0.05", "bc6h_ufloat"), ("0.0001", "rgb9e5")):
        me = os.path.join(work, "max_error_" + form)
        run([tool, "convert", mat, "--out", me, "--engine", "all", "--max-error", bound, "--quiet",
             "--formats", "ktx2,json", "--beyond", "clamp"])
        side = json.load(open(os.path.join(me, name + ".json")))
        manifest = json.load(open(os.path.join(me, "web", name + ".manifest.json")))
        expect(side["compression"]["format"] == form and manifest["texture"]["block_format"] ==
               ("bc6h_ufloat" if form != "rgb9e5" else "none")
               and not os.path.exists(os.path.join(me, name + ".brdfc")),
               f"--max-error {bound} --engine: {side['compression']['format']}, manifest {manifest['texture']}")
    print("--compress compact --engine refused in one line; --max-error 0.05 / 0.0001 with --engine: "
          "BC6H / RGB9E5 (no compact form)")


def main():
    tool, source, mcs, mono = sys.argv[1:5]
    work = tempfile.mkdtemp(prefix="brdf_engine_checks_")
    mat = os.path.join(work, "gold_like.json")
    json.dump(MATERIAL, open(mat, "w"))
    out = os.path.join(work, "out")
    # --beyond clamp: the reference layout (θin 0/20/40/60, 2 × 2 tiles) these checks spell out;
    # the default fill's 9 slices go through the same writers (web_browser_test.py runs them).
    run([tool, "convert", mat, "--out", out, "--engine", "all", "--quiet", "--formats", "ktx2,json",
         "--beyond", "clamp"])
    # A misspelt engine: one line, exit 1, nothing written.
    bad = subprocess.run([tool, "convert", mat, "--out", os.path.join(work, "bad"), "--engine",
                          "unity,unrael"], capture_output=True, text=True)
    expect(bad.returncode == 1 and bad.stderr.strip() ==
           "brdf: error: unknown engine 'unrael' (known: unity, unreal, godot, web, all)"
           and not os.path.exists(os.path.join(work, "bad")),
           f"--engine unrael: exit {bad.returncode}, stderr {bad.stderr!r}")
    check_fits(tool, mat, work)
    words, want = check_dds(out, "gold_like")
    check_unity(out, "gold_like", mcs, mono, work, words, want)
    check_bc6h(tool, mat, mcs, mono, work)
    check_unreal(out, work)
    check_godot(out, "gold_like")
    check_ibl_pack(out, "gold_like", ["unity", "unreal", "godot", "web"])
    # An atlas of two materials: one pack row per cell, in cell order.
    lamb = os.path.join(work, "grey.json")
    json.dump({"model": "lambert", "rho": [0.5, 0.4, 0.3]}, open(lamb, "w"))
    run([tool, "atlas", mat, lamb, "--out", os.path.join(work, "atlas", "pair"), "--engine", "web,godot", "--quiet"])
    check_ibl_pack(os.path.join(work, "atlas"), "pair", ["web", "godot"])
    lambert_row = json.load(open(os.path.join(work, "atlas", "web", "pair.manifest.json")))["ibl"]["cells"][1]
    e = np.asarray(lambert_row["albedo_rgb"])
    expect(lambert_row["material"] == "grey" and np.abs(e[8:] - [0.5, 0.4, 0.3]).max() < 0.005,
           f"atlas cell 1 is not the Lambertian: {lambert_row['material']}, E {e[32]}")
    if FAILURES:
        print(f"{len(FAILURES)} check(s) failed; kept {work}")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
