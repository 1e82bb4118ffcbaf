"""Models that fail in each way a model can: the tests check every failure is reported, named."""
import numpy as np


class NoCompute:
    pass


class WrongLength:
    def compute(self, step):
        return np.zeros((step.n_vertices - 1, 3))


class NaNVelocity:
    def compute(self, step):
        v = np.array(step.conormal)
        v[5, 1] = np.nan
        return v


class NotArray:
    def compute(self, step):
        return [[0.0, 0.0, 0.0]] * step.n_vertices


class Raises:
    def compute(self, step):
        if step.iteration == 2:
            raise ValueError("boom at iteration 2")
        return np.array(step.conormal)


class KeptStep:
    """Keeps the Step past its call: using it later is refused, not a crash."""
    kept = None

    def compute(self, step):
        if KeptStep.kept is not None:
            KeptStep.kept.distance  # noqa: B018  (raises)
        KeptStep.kept = step
        return np.array(step.conormal)
