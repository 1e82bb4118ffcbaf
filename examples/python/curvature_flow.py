"""A cap shrinking by its geodesic curvature on the unit sphere (curve-shortening flow), written in
Python with the engine's helpers: V = −κ n_Σ with κ the curvature of the level sets of d.

A cap of geodesic radius r has κ = cot r, so dr/dt = −cot r and cos r(t) = cos r0 · e^t: the
area 2π(1 − cos r) is known at every time. Run: python3 examples/python/curvature_flow.py
"""
import math

import numpy as np

import bodyfit


class CurvatureFlow:
    """Normal speed −κ: each front moves toward its centre of curvature."""

    parameters = [bodyfit.Parameter("smoothing", 1.0, unit="h", description="H¹ smoothing length of κ, in edge lengths")]
    outputs = ["front_curvature"]

    def compute(self, step):
        h = step.mesh_size
        # κ is singular at the centre of a disk (|κ| ~ 1/h there): clipped. An explicit curvature
        # speed is stable for Δt below about h²/4; the H¹ smoothing (length ℓ) damps the modes of
        # wavelength below ℓ, which lets Δt grow to about ℓ²/4.
        kappa = step.smooth(np.clip(step.front_curvature, -0.1 / h, 0.1 / h), self.smoothing * h)
        front = np.abs(step.distance) < h
        return {"normal_speed": -kappa, "metrics": {"front_curvature": float(np.mean(kappa[front]))}}


if __name__ == "__main__":
    r0, final = math.radians(60), 0.4
    case = {
        "surface": {"generator": "sphere", "h": 0.04},
        "region": {"shape": "cap", "axis": [0.0, 0.0, 1.0], "angle": math.degrees(r0)},
        "time": {"dt": 0.005, "final_time": final},
        "output": {"png_every": 0},
    }
    result = bodyfit.run(case, out="out/curvature_flow", model=CurvatureFlow(), overwrite=True, progress=False)
    t, area = np.asarray(result.history["time"]), np.asarray(result.history["area"])
    exact = 2 * math.pi * (1 - math.cos(r0) * np.exp(t))
    print(f"t = {t[-1]:.2f}: |G| = {area[-1]:.4f}, exact {exact[-1]:.4f} "
          f"(error {100 * abs(area[-1] / exact[-1] - 1):.2f} %)")
