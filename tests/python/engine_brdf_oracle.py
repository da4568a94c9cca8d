#!/usr/bin/python3
"""Independent numpy transcription of the engines' published shading functions, for
tests/processing/engine_models_test.cpp.

Reads lines "MODEL P1 P2 ... ; LX LY LZ VX VY VZ" on stdin (parameters in the material file's
order, RGB ones as three numbers) and prints one line "R G B" of f_r (1/sr) per input line.

Written from the shader sources, not from brdf-toolchain's C++:
  Unreal Engine   Engine/Shaders/Private/BRDF.ush (D_GGX, Vis_SmithJointApprox, F_Schlick,
                  Diffuse_Lambert) and ShadingModels.ush (DefaultLitBxDF), with
                  DiffuseColor = BaseColor - BaseColor*Metallic and
                  SpecularColor = ComputeF0(Specular, BaseColor, Metallic).
  Unity HDRP      com.unity.render-pipelines.core ShaderLibrary/BSDF.hlsl (F_Schlick, D_GGX,
                  V_SmithJointGGX, DisneyDiffuse) and CommonMaterial.hlsl, HDRP Lit.hlsl
                  (ComputeDiffuseColor, ComputeFresnel0 with 0.04; specular colour with the Lit
                  shader's energy-conserving option: baseColor *= 1 - Max3(specularColor)).
  Unity URP       com.unity.render-pipelines.universal ShaderLibrary/BRDF.hlsl
                  (InitializeBRDFData, InitializeBRDFDataDirect, DirectBRDFSpecular), the
                  result divided by pi because URP's punctual light carries the pi.
"""
import sys

import numpy as np

PI = np.pi


def pow5(x):
    return x * x * x * x * x


def half_vector(l, v):
    h = l + v
    return h / np.linalg.norm(h)


def unreal_defaultlit(p, l, v):
    base = np.array(p[0:3])
    metallic, specular, roughness = p[3], p[4], p[5]
    n = np.array([0.0, 0.0, 1.0])
    h = half_vector(l, v)
    nol = float(np.dot(n, l))
    nov = min(1.0, abs(float(np.dot(n, v))) + 1e-5)  # saturate(abs(NoV) + 1e-5)
    noh = float(np.dot(n, h))
    voh = float(np.dot(v, h))
    a2 = max(roughness ** 4, 1e-12)
    d = (noh * a2 - noh) * noh + 1.0
    D = a2 / (PI * d * d)
    a = np.sqrt(a2)
    vis_v = nol * (nov * (1 - a) + a)
    vis_l = nov * (nol * (1 - a) + a)
    Vis = 0.5 / (vis_v + vis_l)
    f0 = 0.08 * specular * (1 - metallic) + base * metallic  # lerp(0.08 Specular, Base, Metallic)
    fc = pow5(1 - voh)
    F = np.clip(50.0 * f0[1], 0.0, 1.0) * fc + (1 - fc) * f0
    diffuse = (base - base * metallic) / PI
    return diffuse + D * Vis * F


def hdrp_lit(p, l, v, specular_color):
    if specular_color:
        base = np.array(p[0:3])
        f0 = np.array(p[3:6])
        smoothness = p[6]
        diffuse_color = base * (1.0 - max(f0))
    else:
        base = np.array(p[0:3])
        metallic, smoothness = p[3], p[4]
        diffuse_color = base * (1 - metallic)
        f0 = 0.04 + (base - 0.04) * metallic  # lerp(0.04, base, metallic)
    perceptual = 1 - smoothness
    alpha = max(perceptual * perceptual, 1e-4)
    h = half_vector(l, v)
    nol = l[2]
    nov = max(v[2], 0.0001)
    noh = h[2]
    loh = float(np.dot(l, h))
    lov = float(np.dot(l, v))
    a2 = alpha * alpha
    s = (noh * a2 - noh) * noh + 1.0
    D = a2 / (PI * s * s)
    lambda_v = nol * np.sqrt((-nov * a2 + nov) * nov + a2)
    lambda_l = nov * np.sqrt((-nol * a2 + nol) * nol + a2)
    V = 0.5 / (lambda_v + lambda_l)
    F = f0 + (1 - f0) * pow5(1 - loh)
    fd90 = 0.5 + (perceptual + perceptual * lov)
    light_scatter = 1 + (fd90 - 1) * pow5(1 - nol)
    view_scatter = 1 + (fd90 - 1) * pow5(1 - nov)
    disney = light_scatter * view_scatter / 1.03571 / PI
    return diffuse_color * disney + F * D * V


def urp_lit(p, l, v, specular_setup):
    albedo = np.array(p[0:3])
    if specular_setup:
        spec = np.array(p[3:6])
        smoothness = p[6]
        diffuse = albedo * (1 - spec)
        specular = spec
    else:
        metallic, smoothness = p[3], p[4]
        one_minus_reflectivity = 0.96 - metallic * 0.96
        diffuse = albedo * one_minus_reflectivity
        specular = 0.04 + (albedo - 0.04) * metallic
    perceptual = 1 - smoothness
    roughness = max(perceptual * perceptual, 2.0 ** -7)
    roughness2 = max(roughness * roughness, 2.0 ** -14)
    normalization = roughness * 4 + 2
    h = half_vector(l, v)
    noh = h[2]
    loh = float(np.dot(l, h))
    d = noh * noh * (roughness2 - 1) + 1.00001
    spec_term = roughness2 / ((d * d) * max(0.1, loh * loh) * normalization)
    return (diffuse + spec_term * specular) / PI


MODELS = {
    "unreal-defaultlit": lambda p, l, v: unreal_defaultlit(p, l, v),
    "unity-hdrp-lit": lambda p, l, v: hdrp_lit(p, l, v, False),
    "unity-hdrp-lit-specular": lambda p, l, v: hdrp_lit(p, l, v, True),
    "unity-urp-lit": lambda p, l, v: urp_lit(p, l, v, False),
    "unity-urp-lit-specular": lambda p, l, v: urp_lit(p, l, v, True),
}


def main():
    for line in sys.stdin:
        line = line.strip()
        if not line:
            continue
        head, dirs = line.split(";")
        fields = head.split()
        model, params = fields[0], [float(x) for x in fields[1:]]
        d = [float(x) for x in dirs.split()]
        l = np.array(d[0:3])
        v = np.array(d[3:6])
        f = MODELS[model](params, l, v)
        print("%.17g %.17g %.17g" % (f[0], f[1], f[2]))


if __name__ == "__main__":
    main()
