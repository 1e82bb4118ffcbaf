"""The paper's first example with its velocity written in Python: V = speed · ∇_S d.

From the command line (the `python` model):
    bodyfit run examples/python/sphere_cap_python.toml -o out/sphere_cap_python
From Python:
    python3 examples/python/conormal.py
"""
import bodyfit


class Conormal:
    """V = speed · ∇_S d: the unit conormal, extended by the gradient of the signed distance."""

    name = "py_conormal"
    parameters = [bodyfit.Parameter("speed", 1.0, unit="length/time", description="factor multiplying V")]
    outputs = [bodyfit.Output("speed", unit="length/time", description="the factor of the step")]

    def configure(self, params):
        self.speed = params["speed"]

    def compute(self, step):
        return {"velocity": self.speed * step.conormal, "metrics": {"speed": self.speed}}


if __name__ == "__main__":
    import math
    case = {  # meshes/cases/sphere_cap.toml as a dict; [model] holds the object's parameters
        "surface": {"generator": "sphere", "h": 0.05},
        "region": {"shape": "cap", "axis": [0.0, 0.0, 1.0], "angle": 45.0},
        "model": {"speed": 1.0},
        "time": {"cfl": 0.5, "final_time": math.pi / 4},
        "remesh": {"hmax": 0.05, "hmin": 0.005, "hausd": 0.001},
    }
    result = bodyfit.run(case, out="out/sphere_cap_python", model=Conormal(), overwrite=True)
    area = result.history["area"]
    print(f"{result.iteration} iterations, |G| = {area[len(area) - 1]:.4f} (exact: {2 * math.pi:.4f})")
