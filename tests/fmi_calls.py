"""A bare ctypes driver for the joint FMU's binary: exact FMI 2 / FMI 3 calling sequences, every status
and every log message captured. Independent of fmpy, so a test controls each call."""

from __future__ import annotations

import ctypes as C
import zipfile
from pathlib import Path
from xml.etree import ElementTree

OK, WARNING, DISCARD, ERROR, FATAL = range(5)
ME, CS = 0, 1  # fmi2ModelExchange, fmi2CoSimulation

LOGGER2 = C.CFUNCTYPE(None, C.c_void_p, C.c_char_p, C.c_int, C.c_char_p, C.c_char_p)
LOGGER3 = C.CFUNCTYPE(None, C.c_void_p, C.c_int, C.c_char_p, C.c_char_p)


class Callbacks2(C.Structure):
    _fields_ = [
        ("logger", LOGGER2),
        ("allocateMemory", C.c_void_p),
        ("freeMemory", C.c_void_p),
        ("stepFinished", C.c_void_p),
        ("componentEnvironment", C.c_void_p),
    ]


def unpack(fmu: Path, into: Path) -> tuple[Path, str, int]:
    """Extract `fmu`; returns (folder, instantiation token, FMI major version)."""
    with zipfile.ZipFile(fmu) as z:
        z.extractall(into)
    root = ElementTree.parse(into / "modelDescription.xml").getroot()
    version = int(root.get("fmiVersion")[0])
    return into, root.get("guid") or root.get("instantiationToken"), version


def _c(a):
    """A ctypes argument: floats as double, ints and bools widened to 64 bits (the callee reads the
    low bytes it needs, so no upper half of a register is left undefined), the rest as given."""
    if isinstance(a, float):
        return C.c_double(a)
    if isinstance(a, int):
        return C.c_size_t(a)
    return a


def doubles(*values: float):
    return (C.c_double * max(1, len(values)))(*values)


def vrs(*refs: int):
    return (C.c_uint32 * max(1, len(refs)))(*refs)


class Fmu:
    """One loaded binary (FMI 2 or 3) and a log of (status, category, message) from its instances."""

    def __init__(self, folder: Path, token: str, version: int) -> None:
        self.folder, self.token, self.version = folder, token, version
        sub = "linux64" if version == 2 else "x86_64-linux"
        self.lib = C.CDLL(str(folder / "binaries" / sub / "FlexJoint.so"))
        self.log: list[tuple[int, str, str]] = []
        if version == 2:
            self._logger = LOGGER2(lambda env, name, status, cat, msg: self._record(status, cat, msg, name))
            self._callbacks = Callbacks2(self._logger, None, None, None, None)
        else:
            self._logger = LOGGER3(lambda env, status, cat, msg: self._record(status, cat, msg))
        for f in (
            ("fmi2Instantiate",)
            if version == 2
            else ("fmi3InstantiateModelExchange", "fmi3InstantiateCoSimulation")
        ):
            getattr(self.lib, f).restype = C.c_void_p
        self.names: list[bytes] = []

    def _record(self, status: int, category: bytes, message: bytes, name: bytes | None = None) -> None:
        self.log.append((status, category.decode(), message.decode()))
        if name is not None:
            self.names.append(name)

    def instantiate(
        self,
        kind: int = CS,
        *,
        name: str = "joint",
        logging: bool = True,
        event_mode: bool = False,
        resources: str | None = None,
    ):
        """A new instance (None when instantiation fails); `resources`: the FMI 2 resource location
        to pass (default: the folder's file URI)."""
        if self.version == 2:
            uri = resources or (self.folder / "resources").as_uri()
            args = (
                name.encode(),
                kind,
                self.token.encode(),
                uri.encode(),
                C.byref(self._callbacks),
                0,
                logging,
            )
            return self.lib.fmi2Instantiate(*map(_c, args))
        res = str(self.folder / "resources") + "/"
        if kind == ME:
            args = (name.encode(), self.token.encode(), res.encode(), False, logging, None, self._logger)
            return self.lib.fmi3InstantiateModelExchange(*map(_c, args))
        args = (name.encode(), self.token.encode(), res.encode(), False, logging, event_mode, False)
        return self.lib.fmi3InstantiateCoSimulation(*map(_c, args), None, _c(0), None, self._logger, None)

    def __call__(self, function: str, instance, *args) -> int:
        """Call `function(instance, *args)`; floats are passed as doubles, bools and ints as ints."""
        return getattr(self.lib, function)(C.c_void_p(instance), *map(_c, args))

    def start(self, instance, *, start: float = 0.0, stop: float | None = None) -> None:
        """Initialization Mode at `start` and out of it; asserts every status is OK."""
        if self.version == 2:
            assert (
                self("fmi2SetupExperiment", instance, 0, 0.0, start, int(stop is not None), stop or 0.0) == OK
            )
            assert self("fmi2EnterInitializationMode", instance) == OK
            assert self("fmi2ExitInitializationMode", instance) == OK
        else:
            args = (False, 0.0, start, stop is not None, stop or 0.0)
            assert self("fmi3EnterInitializationMode", instance, *args) == OK
            assert self("fmi3ExitInitializationMode", instance) == OK

    def get(self, instance, *refs: int) -> list[float]:
        out = doubles(*([0.0] * len(refs)))
        if self.version == 2:
            status = self("fmi2GetReal", instance, vrs(*refs), len(refs), out)
        else:
            status = self("fmi3GetFloat64", instance, vrs(*refs), len(refs), out, len(refs))
        assert status == OK, self.log[-1:]
        return list(out[: len(refs)])

    def set(self, instance, refs: list[int], values: list[float]) -> int:
        if self.version == 2:
            return self("fmi2SetReal", instance, vrs(*refs), len(refs), doubles(*values))
        return self("fmi3SetFloat64", instance, vrs(*refs), len(refs), doubles(*values), len(refs))

    def free(self, instance) -> None:
        self(f"fmi{self.version}FreeInstance", instance)
