from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class ThirdPartySpring(Fmi2Slave):
    """A co-simulation-only force element: f = -(k s + c v), computed in do_step."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.k = 3.0
        self.c = 0.5
        self.s = 0.0
        self.v = 0.0
        self.f = 0.0
        self.register_variable(
            Real(
                "theta.k",
                causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.tunable,
                getter=lambda: self.k,
                setter=lambda x: setattr(self, "k", x),
            )
        )
        self.register_variable(
            Real(
                "theta.c",
                causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.tunable,
                getter=lambda: self.c,
                setter=lambda x: setattr(self, "c", x),
            )
        )
        self.register_variable(
            Real(
                "theta.s",
                causality=Fmi2Causality.input,
                getter=lambda: self.s,
                setter=lambda x: setattr(self, "s", x),
            )
        )
        self.register_variable(
            Real(
                "theta.v",
                causality=Fmi2Causality.input,
                getter=lambda: self.v,
                setter=lambda x: setattr(self, "v", x),
            )
        )
        self.register_variable(Real("theta.f", causality=Fmi2Causality.output, getter=lambda: self.f))

    def do_step(self, current_time, step_size):
        self.f = -(self.k * self.s + self.c * self.v)
        return True
