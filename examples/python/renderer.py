"""A renderer's environment light: directions and pdfs from an EXR sky.

Make the sky first (any lat-long EXR, .hdr or PNG will do):
    cargo run --release --example synth_maps -- synth-maps
then: python examples/python/renderer.py [synth-maps/clear-sky_1024x512_f32.exr]

Each frame draws its own blue-noise set (seed = frame): the estimates are
unbiased, so averaging frames converges. The irradiance on an upward
surface is estimated with light samples alone, then combined with cosine
(BSDF-like) samples by multiple importance sampling, which needs the light
pdf of directions tessera did not draw: tessera.pdf.
"""

import sys

import numpy as np

import tessera

path = sys.argv[1] if len(sys.argv) > 1 else "synth-maps/clear-sky_1024x512_f32.exr"
sky = tessera.Map(path)  # read once; every call below reuses it
normal = np.array([0.0, 0.0, 1.0])
n = 256


def radiance(directions):
    # the pdf is the map's luminance over its integral
    return tessera.pdf(directions, map=sky) * sky.integral


light_only, mis = [], []
rng = np.random.default_rng(0)
for frame in range(16):
    w, p_light = tessera.sphere(n, map=sky, seed=frame, pdf=True)
    cos = np.clip(w @ normal, 0.0, None)
    light_only.append(np.mean(radiance(w) * cos / p_light))
    # cosine-weighted hemisphere samples, and tessera's pdf for them
    u1, u2 = rng.random(n), rng.random(n)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    b = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], axis=1)
    p_bsdf_b, p_bsdf_w = b[:, 2] / np.pi, cos / np.pi
    p_light_b = tessera.pdf(b, map=sky)
    # balance heuristic: each sample weighted by its pdf over the sum
    from_light = radiance(w) * cos / (p_light + p_bsdf_w)
    from_bsdf = radiance(b) * b[:, 2] / (p_light_b + p_bsdf_b)
    mis.append(np.mean(from_light) + np.mean(from_bsdf))

# a reference: 4096 lights with exact powers (their cells partition the sphere)
lights = tessera.lights(path, 4096)
reference = np.sum(lights["luminance"] * np.clip(lights["direction"] @ normal, 0.0, None))

print(f"{sky!r}: {n} light samples a frame, 16 frames")
print(f"irradiance, 4096 lights:    {reference:.6g}")
print(f"irradiance, light sampling: {np.mean(light_only):.6g} (frame spread {np.std(light_only):.3g})")
print(f"irradiance, MIS:            {np.mean(mis):.6g} (frame spread {np.std(mis):.3g})")
