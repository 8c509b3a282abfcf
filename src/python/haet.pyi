"""HAET, a granular-flow simulator, driven from Python (docs/python.md)."""
from os import PathLike
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike]

FROZEN: int
"""The flag bit of a particle that is not integrated (Simulation.flags)."""


class ScenarioError(ValueError):
    """A scenario that cannot be run."""
    file: str
    line: int
    """1-based; 0 when unknown."""
    key: str
    """The dotted key, e.g. "insert[2].radius"; empty when none."""
    message: str
    """What is wrong, without the place and key."""


class SimulationError(RuntimeError):
    """The simulation blew up (a NaN, an overlap beyond the limit); the outputs written so far are kept."""


class CheckpointError(ValueError):
    """A checkpoint file that is not whole, of a later format or of another scenario."""


class WallInfo(TypedDict, total=False):
    """One wall of Simulation.walls (a copy)."""
    name: str
    """As the scenario names it; may be empty."""
    index: int
    """k of the scenario's walls[k], from 1."""
    kind: str
    """"plane", "mesh" (segments, polylines, triangles), "arc", "cylinder" or "disc"."""
    velocity: npt.NDArray[np.float64]
    """The constant translation velocity (D,) [m/s], without an oscillation."""
    angular_velocity: Union[float, npt.NDArray[np.float64], None]
    """[rad/s]: 2D a number (about z), 3D (3,); None for a plane."""
    point: npt.NDArray[np.float64]
    """A plane's: a point of it now (D,) [m]."""
    normal: npt.NDArray[np.float64]
    """A plane's: its unit normal into the domain (D,)."""
    rotation: npt.NDArray[np.float64]
    """Another wall's pose now: a point b as the scenario gives it is at rotation @ b + shift; (D, D)."""
    shift: npt.NDArray[np.float64]
    """(D,) [m], with rotation."""


class Simulation:
    """A run of a scenario, advanced from Python. Outputs as `haet run` writes them go to `out`; without it to a
    temporary directory that close() removes. A context manager: leaving it calls close()."""

    @staticmethod
    def from_file(path: _Path, *, out: Optional[_Path] = None, threads: int = 0,
                  set: Sequence[str] = ()) -> "Simulation": ...
    @staticmethod
    def from_string(toml: str, *, out: Optional[_Path] = None, threads: int = 0, set: Sequence[str] = (),
                    path: _Path = "<string>") -> "Simulation": ...
    @staticmethod
    def from_dict(scenario: Mapping[str, Any], *, out: Optional[_Path] = None, threads: int = 0,
                  set: Sequence[str] = ()) -> "Simulation": ...
    @staticmethod
    def load(checkpoint: _Path, scenario: _Path, *, out: Optional[_Path] = None, threads: int = 0,
             set: Sequence[str] = ()) -> "Simulation": ...

    def run(self, until: float) -> None:
        """Runs to simulated time `until` [s]. Ctrl-C: KeyboardInterrupt at the end of a step (the run may go on)."""
    def step(self, n: int = 1) -> None:
        """n time steps; ValueError for a pure event-driven run."""
    def finish(self) -> str:
        """Writes the last state as `haet run` does at its end; returns the status ("completed", ...)."""
    def close(self) -> None: ...
    def save(self, path: _Path) -> None:
        """A checkpoint of the state now, for Simulation.load."""
    def add_particles(self, positions: npt.ArrayLike, radii: npt.ArrayLike, velocities: Optional[npt.ArrayLike] = None,
                      material: Union[str, int, None] = None) -> None:
        """Adds spheres (2D: disks) as an inlet does, mass from the material's density, at rest by default. Their
        ids come from the counter the inlets draw from: never one a particle of the run had."""
    def remove(self, ids: npt.ArrayLike) -> None:
        """Removes the particles with these ids, as an outlet does."""
    def set_wall(self, wall: Union[str, int], *, velocity: Optional[npt.ArrayLike] = None,
                 angular_velocity: Union[float, npt.ArrayLike, None] = None) -> None:
        """Sets the translation velocity (D,) [m/s] and/or the angular velocity [rad/s] (2D: a number about z; 3D:
        (3,), its direction the axis) of the wall named `wall` (or walls[wall] of the scenario, from 1), from the
        current time on, with the wall where it is (no jump). Planes translate only; an event-driven run moves
        planes only; a hybrid run raises ValueError. A checkpoint holds the change."""
    def __enter__(self) -> "Simulation": ...
    def __exit__(self, *args: Any) -> None: ...

    @property
    def time(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def method(self) -> str: ...
    @property
    def dimension(self) -> int: ...
    @property
    def directory(self) -> Path: ...
    @property
    def status(self) -> str: ...
    @property
    def closed(self) -> bool: ...
    @property
    def series(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def run_info(self) -> dict[str, Any]: ...
    @property
    def n_particles(self) -> int: ...
    @property
    def walls(self) -> list[WallInfo]:
        """The scenario's walls in its order, and how each moves and where it is now (a copy)."""
    @property
    def gravity(self) -> npt.NDArray[np.float64]: ...
    @gravity.setter
    def gravity(self, g: npt.ArrayLike) -> None: ...

    # Views of the particle store (no copy): valid until the run goes on or particles are added or removed.
    # Writing into them changes the state (the engine is told before the run goes on); read-only in hybrid runs.
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def velocities(self) -> npt.NDArray[np.float64]: ...
    @property
    def angular_velocities(self) -> npt.NDArray[np.float64]: ...
    @property
    def radii(self) -> npt.NDArray[np.float64]: ...
    @property
    def masses(self) -> npt.NDArray[np.float64]: ...
    @property
    def materials(self) -> npt.NDArray[np.uint16]: ...
    @property
    def flags(self) -> npt.NDArray[np.uint8]: ...
    @property
    def forces(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def torques(self) -> Optional[npt.NDArray[np.float64]]: ...
    # Copies
    @property
    def ids(self) -> npt.NDArray[np.uint64]: ...
    @property
    def modes(self) -> npt.NDArray[np.uint8]: ...
