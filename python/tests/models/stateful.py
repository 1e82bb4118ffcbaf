"""A conormal model with state (the calls so far) and a review that rejects once, to test
checkpoints, --resume and reviews with a Python model; it also checks the Step's helpers."""
import os
import signal

import numpy as np

import bodyfit


class Counting:
    name = "counting"
    parameters = [bodyfit.Parameter("speed", 1.0, unit="length/time", min=0.0),
                  bodyfit.Parameter("reject_at", -1, description="reject the first attempt of this iteration"),
                  bodyfit.Parameter("interrupt_at", -1, description="send SIGINT to this process in this iteration")]
    outputs = ["calls", "mass_error", bodyfit.Output("speed_field", kind="field")]
    may_reject = True
    state_version = 2

    def __init__(self):
        self.calls = 0

    def configure(self, params):
        self.speed = params["speed"]
        self.reject_at = params["reject_at"]
        self.interrupt_at = params["interrupt_at"]

    def compute(self, step):
        self.calls += 1
        if step.iteration == self.interrupt_at:
            os.kill(os.getpid(), signal.SIGINT)
        # The mass matrix (scipy) sums to the area, as the face areas do.
        mass = step.mass_matrix()
        mass_error = abs(mass.sum() - np.sum(step.face_areas))
        v = self.speed * step.conormal
        return {"velocity": v, "metrics": {"calls": float(self.calls), "mass_error": mass_error},
                "fields": {"speed_field": np.linalg.norm(v, axis=1)}}

    def review(self, candidate, attempt):
        if candidate.iteration == self.reject_at and attempt == 0:
            return bodyfit.Review(accept=False, reason="first attempt refused by the test")
        return None

    def save_state(self):
        return {"calls": self.calls}

    def load_state(self, state):
        self.calls = state["calls"]
