"""Types of the compiled engine module (crates/hexadyn-py), for type checkers and editors.

Every class, function and constant the module defines is here (tests/python/test_typing.py
compares this stub with the module at run time, mypy's stubtest); the doc comments of the
Rust bindings say what the dicts hold.
"""

import os
from typing import Any, Callable, Self, final

import numpy as np
import numpy.typing as npt
from typing_extensions import disjoint_base

_Path = str | os.PathLike[str]
_Floats = npt.NDArray[np.float64]
_Overrides = dict[str, Any] | None
_Progress = Callable[[float, float], object] | None

__all__ = [
    "__version__",
    "STANDARD_GRAVITY",
    "SHIPPED_ROBOTS",
    "LEG_COUNT",
    "PHASE_CODES",
    "load_scenario",
    "run_scenario",
    "scenario_model",
    "terrain_triangles",
    "robot_properties",
    "specific_resistance",
    "shipped_robot_text",
    "robot_urdf",
    "robot_mjcf",
    "monte_carlo_distributions",
    "encode_command",
    "decode_command",
    "encode_reply",
    "decode_reply",
    "robot_run",
    "robot_emulate",
    "Multibody",
    "PantographHexapod",
    "UrdfHexapod",
    "Kinematics",
    "LegModel",
]

__version__: str
STANDARD_GRAVITY: float
LEG_COUNT: int
SHIPPED_ROBOTS: list[str]
PHASE_CODES: dict[str, int]

# Scenarios (scenario.rs)
def load_scenario(path: _Path, overrides: _Overrides = None) -> dict[str, Any]: ...
def run_scenario(
    path: _Path,
    progress: _Progress = None,
    overrides: _Overrides = None,
    timeseries: bool = True,
    chunk: Callable[[dict[str, _Floats], dict[str, str]], object] | None = None,
    chunk_rows: int = 10000,
) -> dict[str, Any]: ...
def scenario_model(text: str, origin: str) -> dict[str, Any]: ...
def terrain_triangles(
    path: _Path,
    overrides: _Overrides = None,
    half_width_m: float = 5.0,
    centre_x_m: float = 0.0,
    centre_y_m: float = 0.0,
) -> tuple[_Floats, npt.NDArray[np.uint32]]: ...

# Robot descriptions (schema.rs, urdf.rs, pantograph.rs, monte_carlo.rs)
def robot_properties(text: str, origin: str = "robot description") -> dict[str, Any]: ...
def specific_resistance(energy_j: float, mass_kg: float, distance_m: float) -> float: ...
def shipped_robot_text(name: str) -> str: ...
def robot_urdf(text: str, origin: str = "robot description") -> str: ...
def robot_mjcf(text: str, origin: str = "robot description") -> str: ...
def monte_carlo_distributions(robot: str = ...) -> dict[str, Any]: ...

# The robot link (link.rs)
def encode_command(seq: int, setpoints: list[int], version: int = 3, run: int = 0) -> bytes: ...
def decode_command(data: bytes, version: int = 3) -> tuple[int, int, list[int]]: ...
def encode_reply(leg: int, seq: int, counts: list[int], currents_ma: list[int], supply: int, version: int = 3) -> bytes: ...
def decode_reply(data: bytes, version: int = 3) -> tuple[int, int, list[int], list[int], int]: ...
def robot_run(
    scenario: _Path,
    link: _Path,
    progress: _Progress = None,
    overrides: _Overrides = None,
    emulated: bool = False,
    faults: dict[str, Any] | None = None,
    stall: tuple[float, float] | None = None,
) -> dict[str, Any]: ...
def robot_emulate(
    scenario: _Path,
    link: _Path,
    faults: dict[str, Any] | None = None,
    idle_timeout_s: float | None = None,
    ready: Callable[[], object] | None = None,
    overrides: _Overrides = None,
) -> dict[str, Any]: ...

@disjoint_base
class Multibody:
    """A multibody model (Section 3.3): M(q), h(q, q'), g(q) and the kinetic energy."""

    def __new__(cls, coordinates: int, bodies: list[dict[str, Any]], gravity: tuple[float, float, float] | list[float] = ...) -> Self: ...
    @property
    def coordinates(self) -> int: ...
    def mass_matrix(self, q: _Floats) -> _Floats: ...
    def nonlinear_effects(self, q: _Floats, qd: _Floats) -> _Floats: ...
    def gravity_forces(self, q: _Floats) -> _Floats: ...
    def kinetic_energy(self, q: _Floats, qd: _Floats) -> float: ...

@final
class PantographHexapod(Multibody):
    """The multibody model of a pantograph robot description (AMRU5)."""

    def __new__(cls, robot_text: str, origin: str = "robot description") -> Self: ...
    def to_mjcf(self) -> str: ...
    def mujoco_state(self, q: _Floats) -> tuple[_Floats, _Floats]: ...
    def feet(self, q: _Floats) -> _Floats: ...

@final
class UrdfHexapod(Multibody):
    """The multibody model of a URDF hexapod (six chains of three joints)."""

    def __new__(cls, text: str, origin: str = "URDF") -> Self: ...
    @staticmethod
    def from_file(path: _Path) -> UrdfHexapod: ...
    @property
    def legs(self) -> list[dict[str, Any]]: ...
    @property
    def base_mass(self) -> float: ...
    @property
    def name(self) -> str: ...
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def foot_radii(self) -> list[float]: ...
    def to_mjcf(self) -> str: ...
    def description_toml(self, joint_names: list[str] | tuple[str, str, str], template: str, origin: str) -> str: ...
    def foot_in_leg(self, leg: int, q: list[float]) -> _Floats: ...
    def inverse(self, leg: int, target: list[float], start: list[float] | None = None) -> tuple[_Floats, bool, float]: ...
    def workspace(self, leg: int, z_min: float, z_max: float) -> dict[str, Any]: ...
    def feet(self, q: _Floats) -> _Floats: ...
    def foot_jacobians(self, q: _Floats) -> _Floats: ...

@final
class Kinematics:
    """The engine's model of a robot description, for drawing (hexadyn view)."""

    def __new__(cls, robot_text: str, origin: str = "robot description") -> Self: ...
    @property
    def leg_mechanism(self) -> str: ...
    @property
    def body_names(self) -> list[str]: ...
    @property
    def leg_point_names(self) -> list[str]: ...
    @property
    def geometry(self) -> dict[str, Any]: ...
    def poses(self, q: _Floats) -> tuple[_Floats, _Floats]: ...
    def leg_points(self, q: _Floats) -> _Floats: ...

@final
class LegModel:
    """One leg's constants and inverse dynamics, for the friction identification."""

    def __new__(cls, robot_text: str | None = None, origin: str = "robot description") -> Self: ...
    def joint(self, leg: int, joint: str) -> dict[str, float]: ...
    def joint_torques(self, leg: int, q: _Floats, qd: _Floats, qdd: _Floats, foot_force: tuple[float, float, float] | list[float] = ...) -> _Floats: ...
