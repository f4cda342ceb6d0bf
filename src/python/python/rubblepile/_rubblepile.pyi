"""Type stub of the extension module `rubblepile._rubblepile` (Rust, src/python/src/lib.rs). Use the package
`rubblepile`, whose classes and functions wrap these; SI units throughout (m, kg, s, rad)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

__version__: str

class RubblepileError(Exception):
    """Any error of rubblepile; the message is the command line's one line."""

    t: Optional[float]
    summary: Optional[Dict[str, Any]]
    last_good_state: Optional[str]

class SceneError(RubblepileError):
    """A scene, argument or run directory that cannot be used (the command line's exit code 2); names the field."""

class RunFailed(RubblepileError):
    """The engine failed: `t` is the last good time (s), `summary` the summary written, `last_good_state` its file."""

class RunStopped(RubblepileError):
    """The run's budget ran out: a checkpoint at `t` (s) was written."""

class Simulation:
    @staticmethod
    def from_scene(
        scene: Union[str, Dict[str, Any]],
        out: Optional[str] = None,
        *,
        force: bool = False,
        checkpoint_every: Optional[float] = None,
        checkpoint_every_sim: Optional[float] = None,
        max_steps: Optional[int] = None,
        max_wall_seconds: Optional[float] = None,
    ) -> "Simulation": ...
    @staticmethod
    def from_run(
        dir: Union[str, PathLike[str]],
        *,
        checkpoint_every: Optional[float] = None,
        checkpoint_every_sim: Optional[float] = None,
        max_steps: Optional[int] = None,
        max_wall_seconds: Optional[float] = None,
    ) -> "Simulation": ...
    def integrate(self, t: Optional[float] = None) -> float:
        """Every output sample up to `t` (s); returns the time reached (s)."""
    def step(self) -> float:
        """The next output sample; returns its time (s)."""
    def checkpoint(self) -> None: ...
    def save(self, dir: Union[str, PathLike[str]], *, force: bool = False) -> None: ...
    def close(self) -> None: ...
    @property
    def t(self) -> float:
        """Simulated time (s)."""
    @property
    def t_end(self) -> float:
        """End time (s)."""
    @property
    def done(self) -> bool: ...
    @property
    def kind(self) -> str: ...
    @property
    def out_dir(self) -> str: ...
    @property
    def temporary(self) -> bool: ...
    @property
    def sample_times(self) -> np.ndarray:
        """Times of every output sample (s)."""
    @property
    def samples_done(self) -> int: ...
    @property
    def wall_seconds(self) -> float:
        """Wall-clock seconds of the run (s)."""
    def _summary_json(self) -> str: ...
    def _state(self) -> Dict[str, np.ndarray]: ...
    def _set_state(self, state: Dict[str, np.ndarray]) -> None:
        """Sets positions (m), velocities (m/s), angular_velocities (rad/s, world frame) of a run of any engine,
        and quaternions or spins_body (rad/s) of an ellipsoid run; float64 arrays, one row per particle."""
    def __enter__(self) -> "Simulation": ...
    def __exit__(self, *args: Any) -> None: ...

def impact(
    target: str,
    out: Optional[str] = None,
    *,
    projectile: str = "P2",
    projectile_radius: Optional[float] = None,
    speed: float = 5000.0,
    angle: float = 45.0,
    seed: int = 1,
    contact_time: float = 90.0,
    t_end: float = 10000.0,
    rtol: Optional[float] = None,
    method: str = "bulirsch-stoer",
    f0: float = 1e-6,
    beta: float = 10.0,
    inertia: str = "gaussian",
    kappa_reading: str = "printed",
    snapshots: Optional[List[float]] = None,
    snapshot_every: Optional[float] = None,
    every: float = 10.0,
    force: bool = False,
    checkpoint_every: Optional[float] = None,
    checkpoint_every_sim: Optional[float] = None,
    impact_parameter_m: Optional[float] = None,
    impact_parameter_frac: Optional[float] = None,
    impact_angle_deg: Optional[float] = None,
    aim_azimuth_deg: Optional[float] = None,
    projectile_spin_rad_s: Optional[List[float]] = None,
    projectile_attitude: Optional[List[float]] = None,
) -> Simulation: ...
def analyze(dir: str, at: Optional[float] = None, *, force: bool = False) -> Tuple[str, List[str]]: ...
def build_aggregate(
    model: str,
    shape: str,
    out: str,
    *,
    particles: Optional[int] = None,
    radius: Optional[float] = None,
    radius_range: Optional[Tuple[float, float]] = None,
    bulk_density: float = 2100.0,
    core_radius: Optional[float] = None,
    seed: int = 1,
    lattice_orientation: str = "perpendicular",
    shake_periods: Optional[float] = None,
    gravity_interval: Optional[int] = None,
    obj_scale: float = 1.0,
    force: bool = False,
) -> str:
    """``rubblepile aggregate build``; returns the report as JSON text (m, kg/m^3)."""

def build_target(
    fragments: int,
    period_hours: float,
    out: str,
    *,
    seed: int = 1,
    r_largest_km: Optional[float] = None,
    r_smallest_km: Optional[float] = None,
    total_mass: Optional[float] = None,
    f0: Optional[float] = None,
    rigidity: float = 1e-4,
    drop_detached: bool = False,
    kappa_reading: str = "printed",
    force: bool = False,
) -> str: ...
def flyby(
    target: str,
    out: str,
    *,
    q_m: float,
    v_inf_km_s: float = 5.8,
    radius_m: Optional[float] = None,
    period_hours: Optional[float] = None,
    planet_mass: float = ...,
    planet_radius_m: float = ...,
    planet_j2: Optional[float] = None,
    planet_pole: Optional[List[float]] = None,
    orientation_deg: Optional[List[float]] = None,
    start_q: float = ...,
    kappa: Optional[float] = None,
    f0: Optional[float] = None,
    rtol: float = 1e-6,
    snapshots: int = 9,
    force: bool = False,
    run: bool = True,
    control: bool = True,
    settle_to_principal: bool = False,
    settle_max_hours: Optional[float] = None,
) -> List[str]: ...
def campaign(
    file: str,
    out: Optional[str] = None,
    *,
    parallel: Optional[int] = None,
    threads_per_run: Optional[int] = None,
    checkpoint_every: Optional[float] = None,
    checkpoint_every_sim: Optional[float] = None,
    max_steps: Optional[int] = None,
    max_wall_seconds: Optional[float] = None,
) -> Tuple[str, Optional[Tuple[str, int]], str, List[Dict[str, Any]]]:
    """`rubblepile campaign FILE`: (closing line, (problem, exit code) or None, campaign directory, one dict per grid
    point: campaign.csv's columns (angle_deg in degrees, q_erg_per_g in erg/g, wall_seconds and final_time in s) and
    action, completed, stopped, dir)."""
def critical_search(
    scene: str,
    out: str,
    *,
    from_hours: float,
    to_hours: float,
    step_hours: float = 0.01,
    force: bool = False,
    branch: bool = False,
    criterion: str = "paper",
    significance: Optional[float] = None,
    coordination_tolerance: Optional[float] = None,
    hold: Optional[float] = None,
    judge_window: Optional[float] = None,
    all_holds: bool = False,
    parallel: int = 1,
    threads_per_hold: Optional[int] = None,
    finish_released: bool = False,
) -> List[str]:
    """`rubblepile spinup critical` (periods in h, hold and judge_window in s): writes out/critical.json and
    out/critical.csv; returns the command line's lines."""
