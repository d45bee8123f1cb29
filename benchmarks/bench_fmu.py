"""Joint FMU benchmark: warm against cold export, our FMU against a PythonFMU build of the same model in fmpy,
and nanoseconds per fmi2DoStep from a tight C loop. Run: python benchmarks/bench_fmu.py"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SLAVE = '''
import numpy as np
from scipy.linalg import expm
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class PyJoint(Fmi2Slave):
    """The body interface of the joint in Python: m a = f - k s - c v, exact zero-order hold."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.m, self.c, self.k, self.f, self.s, self.v = 0.01, 2.0, 800.0, 0.0, 0.0, 0.0
        self._h = None
        for name in ("m", "c", "k"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.tunable))
        self.register_variable(Real("f", causality=Fmi2Causality.input))
        for name in ("s", "v"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        if self._h != step_size:
            a = np.array([[0, 1, 0], [-self.k / self.m, -self.c / self.m, 1 / self.m], [0, 0, 0]]) * step_size
            self._e, self._h = expm(a), step_size
        e = self._e
        self.s, self.v = (e[0, 0] * self.s + e[0, 1] * self.v + e[0, 2] * self.f,
                          e[1, 0] * self.s + e[1, 1] * self.v + e[1, 2] * self.f)
        return True
'''

LOOP = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "fmi2Functions.h"
static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {
    (void)e; (void)n; (void)s; (void)c; (void)m;
}
int main(int argc, char **argv) {
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2ValueReference f = @F@, s = @S@; /* value references from fmus/FlexJoint/config.h */
    fmi2Real load = 2.744, x;
    struct timespec t0, t1;
    long i, n = atol(argv[3]);
    fmi2Component c = fmi2Instantiate("bench", fmi2CoSimulation, argv[2], argv[1], &cb, 0, 0);
    (void)argc;
    fmi2SetupExperiment(c, 0, 0, 0, 0, 0);
    fmi2EnterInitializationMode(c);
    fmi2ExitInitializationMode(c);
    fmi2SetReal(c, &f, 1, &load);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (i = 0; i < n; i++) fmi2DoStep(c, i * 1e-3, 1e-3, 1);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    fmi2GetReal(c, &s, 1, &x);
    printf("%.3f %.17g\n", ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / n, x);
    fmi2FreeInstance(c);
    return 0;
}
"""


def timed(fn, repeat: int = 1) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="bench_fmu_"))
    os.environ["XDG_CACHE_HOME"] = str(work / "cache")  # a cold cache of our own
    from fmpy import extract, read_model_description, simulate_fmu
    from pythonfmu.builder import FmuBuilder

    from designer.export import build
    from designer.export.fmu import export_fmu, value_reference
    from designer.joint import Joint

    joint = Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3, "m": 0.01}})
    path = work / "joint.fmu"
    cold = timed(lambda: export_fmu(joint, path, 2, "body"))
    warm = timed(lambda: export_fmu(joint, path, 2, "body"), repeat=20)
    print(
        f"export: cold (compiles) {cold * 1e3:.1f} ms, warm (cached binary) {warm * 1e3:.2f} ms, "
        f"cold/warm = {cold / warm:.0f}x"
    )

    script = work / "PyJoint.py"
    script.write_text(SLAVE)
    py_fmu = FmuBuilder.build_FMU(script, dest=work)
    run = dict(stop_time=100.0, step_size=1e-3, output_interval=1e-3)
    ours = timed(lambda: simulate_fmu(str(path), start_values={"x.f": 2.744}, output=["x.s"], **run))
    theirs = timed(lambda: simulate_fmu(str(py_fmu), start_values={"f": 2.744}, output=["s"], **run))
    print(
        f"fmpy, 100 s at 1 ms (100000 steps): ours {ours:.2f} s, PythonFMU {theirs:.2f} s, "
        f"PythonFMU/ours = {theirs / ours:.1f}x"
    )

    d = extract(str(path))
    src = Path(d) / "sources"
    refs = {"@F@": value_reference("x", "f"), "@S@": value_reference("x", "s")}
    (work / "loop.c").write_text(LOOP.replace("@F@", str(refs["@F@"])).replace("@S@", str(refs["@S@"])))
    exe = work / "loop"
    files = [str(src / Path(n).name) for n in build.c_sources(2)]
    subprocess.run(
        ["cc", "-std=gnu99", "-O2", f"-I{src}", str(work / "loop.c"), *files, "-o", str(exe), "-lm"],
        check=True,
    )
    guid = read_model_description(d).guid
    n = 10_000_000
    out = subprocess.run(
        [str(exe), f"file://{d}/resources", guid, str(n)], capture_output=True, text=True, check=True
    ).stdout.split()
    print(
        f"C loop: {float(out[0]):.1f} ns per fmi2DoStep (body interface, one axis, {n} steps, "
        f"final x.s = {float(out[1]):.6g} m, F/k = {2.744 / 800:.6g} m)"
    )


if __name__ == "__main__":
    sys.exit(main())
