# A third estimate, independent of both renderers' code: the radiance a flat surface with a
# glTF dielectric material (metallic 0, ior 1.5, base colour c, roughness r) sends towards a
# viewer along wo, lit by the environment map (glint's convention: u = atan2(x, -z)/2pi,
# v = acos(y)/pi, nearest texel) or by a constant sky, for three BRDF models:
#   spec:   the glTF spec's fresnel_mix: (1 - F(v.h)) c/pi + F(v.h) D Vis (Schlick, f0 0.04),
#           single scattering
#   glint:  GGX with Schlick F + Kulla-Conty multiple scattering, diffuse scaled by
#           (1 - Es(mu_o))(1 - Es(mu_i)) / (1 - Es_avg)   (docs/src/reference/pbr.md)
#   cycles: GGX with the exact dielectric Fresnel, energy scaled (Turquin) at mu_o, diffuse
#           scaled by 1 - Es(mu_o) (Cycles 4.x closure.h: closure_layering_weight)
# Diffuse parts are integrated over the map's texels exactly (a sum over texels, each with its
# solid angle); specular lobes by visible-normal sampling (N samples).
# Needs numpy, and bpy to read the .hdr. Normal and view direction in glTF's frame.
# Usage: python3.11 quad.py (ENV.hdr | const) NX NY NZ WX WY WZ c r [N]
import math
import sys

import numpy as np

rng = np.random.default_rng(1)


def load_env(path):
    if path == "const":
        return np.ones((4, 8, 3))
    import bpy

    img = bpy.data.images.load(path)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[::-1, :, :3].astype(np.float64)  # row 0 = top


def lookup(env, d):
    h, w, _ = env.shape
    u = np.arctan2(d[..., 0], -d[..., 2]) / (2 * np.pi) % 1.0
    v = np.arccos(np.clip(d[..., 1], -1, 1)) / np.pi
    i = np.minimum((u * w).astype(int), w - 1)
    j = np.minimum((v * h).astype(int), h - 1)
    return env[j, i]


def texels(env):
    """directions, solid angles and radiance of every texel (centre direction)."""
    h, w, _ = env.shape
    # 4x4 sub-texel points for the diffuse quadrature
    s = 4
    uu = (np.arange(w * s) + 0.5) / (w * s)
    vv = (np.arange(h * s) + 0.5) / (h * s)
    U, V = np.meshgrid(uu, vv)
    th, ph = V * np.pi, U * 2 * np.pi
    d = np.stack([np.sin(th) * np.sin(ph), np.cos(th), -np.sin(th) * np.cos(ph)], -1)
    v0 = np.arange(h * s) / (h * s) * np.pi
    v1 = (np.arange(h * s) + 1) / (h * s) * np.pi
    dom = (2 * np.pi / (w * s)) * (np.cos(v0) - np.cos(v1))
    dom = np.broadcast_to(dom[:, None], U.shape)
    L = np.repeat(np.repeat(env, s, 0), s, 1)
    return d.reshape(-1, 3), dom.reshape(-1), L.reshape(-1, 3)


def frame(n):
    n = n / np.linalg.norm(n)
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    t = np.cross(a, n)
    t /= np.linalg.norm(t)
    b = np.cross(n, t)
    return t, b, n


def ggx_d(cos_h, a):
    a2 = a * a
    c2 = cos_h * cos_h
    return a2 / (np.pi * (c2 * (a2 - 1) + 1) ** 2)


def lam(mu, a):
    mu = np.clip(mu, 1e-7, 1)
    t2 = (1 - mu * mu) / (mu * mu)
    return 0.5 * (np.sqrt(1 + a * a * t2) - 1)


def schlick(f0, c):
    return f0 + (1 - f0) * (1 - c) ** 5


def fresnel_exact(c, eta=1.5):
    c = np.clip(c, 0, 1)
    g2 = eta * eta - 1 + c * c
    g = np.sqrt(g2)
    A = (g - c) / (g + c)
    B = (c * (g + c) - 1) / (c * (g - c) + 1)
    return 0.5 * A * A * (1 + B * B)


def vndf(wo, a, n):
    """Heitz 2018 visible normals, local frame; returns h (n, 3)."""
    u1, u2 = rng.random(n), rng.random(n)
    vh = np.array([a * wo[0], a * wo[1], wo[2]])
    vh /= np.linalg.norm(vh)
    lensq = vh[0] ** 2 + vh[1] ** 2
    T1 = np.array([-vh[1], vh[0], 0]) / math.sqrt(lensq) if lensq > 0 else np.array([1.0, 0, 0])
    T2 = np.cross(vh, T1)
    r = np.sqrt(u1)
    phi = 2 * np.pi * u2
    t1 = r * np.cos(phi)
    t2 = r * np.sin(phi)
    s = 0.5 * (1 + vh[2])
    t2 = (1 - s) * np.sqrt(1 - t1 * t1) + s * t2
    nh = t1[:, None] * T1 + t2[:, None] * T2 + np.sqrt(np.maximum(0, 1 - t1 * t1 - t2 * t2))[:, None] * vh
    h = np.stack([a * nh[:, 0], a * nh[:, 1], np.maximum(1e-7, nh[:, 2])], -1)
    return h / np.linalg.norm(h, axis=1, keepdims=True)


def spec_estimate(wo, a, n, fresnel, radiance):
    """E[F G2/G1 L] over VNDF: the single-scattering lobe's integral against radiance(wi)."""
    h = vndf(wo, a, n)
    vh = h @ wo
    wi = 2 * vh[:, None] * h - wo
    ok = wi[:, 2] > 0
    g1 = 1 / (1 + lam(wo[2], a))
    g2 = 1 / (1 + lam(wo[2], a) + lam(wi[:, 2], a))
    w = np.where(ok, fresnel(vh) * g2 / g1, 0.0)
    L = radiance(wi)
    return (w[:, None] * L).mean(0)


def albedo(mu, a, fresnel, n=200000):
    wo = np.array([math.sqrt(1 - mu * mu), 0, mu])
    return spec_estimate(wo, a, n, fresnel, lambda wi: np.ones((len(wi), 1)))[0]


def main():
    env = load_env(sys.argv[1])
    nrm = np.array([float(x) for x in sys.argv[2:5]])
    wo_w = np.array([float(x) for x in sys.argv[5:8]])
    c = float(sys.argv[8])
    r = float(sys.argv[9])
    N = int(sys.argv[10]) if len(sys.argv) > 10 else 2_000_000
    a = max(r * r, 1e-3)
    t, b, n = frame(nrm)
    M = np.stack([t, b, n])  # world -> local
    wo = M @ (wo_w / np.linalg.norm(wo_w))
    mu_o = wo[2]
    f0 = 0.04
    radiance = lambda wi_local: lookup(env, wi_local @ M)
    # texel quadrature for the broad lobes (local cos and radiance)
    d, dom, L = texels(env)
    mu_i = d @ n
    up = mu_i > 0
    d, dom, L, mu_i = d[up], dom[up], L[up], mu_i[up]
    # 1D albedo tables (F = 1: A+B = E; Schlick: A, B; exact)
    mus = (np.arange(64) + 0.5) / 64
    E = np.array([albedo(m, a, lambda x: np.ones_like(x)) for m in mus])
    B = np.array([albedo(m, a, lambda x: (1 - x) ** 5) for m in mus])
    A = E - B
    Eex = np.array([albedo(m, a, fresnel_exact) for m in mus])
    avg = lambda f: 2 * np.mean(f * mus)
    E_avg = avg(E)
    interp = lambda tab, m: np.interp(m, mus, tab)
    # --- glint
    F_avg = f0 + (1 - f0) / 21
    F_ms = F_avg * F_avg * E_avg / (1 - F_avg * (1 - E_avg))
    layer = f0 * A + B + F_ms * (1 - E)
    layer_avg = avg(layer)
    spec_g = spec_estimate(wo, a, N, lambda x: schlick(f0, x), radiance)
    ms_w = F_ms * (1 - interp(E, mu_o)) * (1 - interp(E, mu_i)) / (np.pi * (1 - E_avg))
    ms_g = ((ms_w * mu_i * dom)[:, None] * L).sum(0)
    dif_w = c / np.pi * (1 - interp(layer, mu_o)) * (1 - interp(layer, mu_i)) / (1 - layer_avg)
    dif_g = ((dif_w * mu_i * dom)[:, None] * L).sum(0)
    glint = spec_g + ms_g + dif_g
    # --- Cycles: exact Fresnel, Turquin scaling at mu_o with Kulla-Conty's F_ms
    Fss = avg(Eex) / E_avg  # the lobe's average Fresnel
    Ess_o = interp(E, mu_o)
    Fms = Fss * E_avg / (1 - Fss * (1 - E_avg))
    scale = 1 + Fms * (1 - Ess_o) / Ess_o
    spec_c = scale * spec_estimate(wo, a, N, fresnel_exact, radiance)
    alb_c = scale * interp(Eex, mu_o)
    dif_c = c / np.pi * (1 - alb_c) * ((mu_i * dom)[:, None] * L).sum(0)
    cycles = spec_c + dif_c
    # --- glTF spec fresnel_mix, single scattering
    h = wo[None, :] + (d @ M.T)
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    vh = h @ wo
    dif_s = ((c / np.pi * (1 - schlick(f0, vh)) * mu_i * dom)[:, None] * L).sum(0)
    spec_s = spec_g
    gltf = spec_s + dif_s
    lum = lambda x: float(np.mean(x))
    print(f"c={c} r={r} mu_o={mu_o:.3f} E_avg={E_avg:.4f} layer_avg={layer_avg:.4f} layer(mu_o)={interp(layer, mu_o):.4f} cycles_alb(mu_o)={alb_c:.4f}")
    print(f"  glint : {lum(glint):.5f}  (spec {lum(spec_g):.5f} ms {lum(ms_g):.5f} diffuse {lum(dif_g):.5f})")
    print(f"  cycles: {lum(cycles):.5f}  (spec {lum(spec_c):.5f} diffuse {lum(dif_c):.5f})")
    print(f"  gltf  : {lum(gltf):.5f}  (spec {lum(spec_s):.5f} diffuse {lum(dif_s):.5f})")
    print(f"  lambert c*irradiance/pi: {lum(c / np.pi * ((mu_i * dom)[:, None] * L).sum(0)):.5f}")


main()
