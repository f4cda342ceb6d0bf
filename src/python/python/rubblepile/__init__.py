"""rubblepile: dynamics of rubble-pile asteroids, from Python.

The three engines of the simulator (interacting ellipsoids, Roig et al. 2003; soft spheres, Zhang et al. 2017; hard
spheres, Richardson et al. 2011) behind one class, :class:`Simulation`, driven by the same run driver as the command
line ``rubblepile run``: a scene run here writes the same run directory (``scene.toml``, ``timeseries.csv``,
``snapshots/``, ``summary.json``, ``manifest.txt``, checkpoints) that the command line writes, readable, resumable
and renderable by it.

Units are SI throughout: metres, kilograms, seconds, radians.

>>> import rubblepile
>>> sim = rubblepile.Simulation.from_scene("targets/examples/two_ellipsoids.toml", "runs/two")  # doctest: +SKIP
>>> sim.integrate()                  # to the scene's t_end (s)  # doctest: +SKIP
>>> sim.energy_error, sim.wall_seconds  # doctest: +SKIP
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Tuple, Union

import numpy as np

from . import _rubblepile
from ._rubblepile import RubblepileError, RunFailed, RunStopped, SceneError
from .runs import read_run, read_snapshot

__version__: str = _rubblepile.__version__

__all__ = [
    "Simulation",
    "RubblepileError",
    "SceneError",
    "RunFailed",
    "RunStopped",
    "analyze",
    "build_target",
    "build_aggregate",
    "campaign",
    "critical_search",
    "flyby",
    "impact",
    "read_run",
    "read_snapshot",
    "spinup",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]

# The state arrays a Simulation exposes, per engine.
_ELLIPSOID_STATE = ("ids", "masses", "positions", "velocities", "angular_velocities", "quaternions", "spins_body",
                    "semi_axes")
_SPHERE_STATE = ("ids", "masses", "positions", "velocities", "angular_velocities", "radii")


class Simulation:
    """One run of a scene, held in memory and advanced output sample by output sample.

    Build it with :meth:`from_scene` (a fresh run) or :meth:`from_run` (continue a run directory from its
    checkpoint). It writes its run directory as it advances, exactly as ``rubblepile run SCENE --out DIR`` does, so
    the files are the command line's (the wall-clock columns aside). Without ``out`` the directory is a temporary
    one, removed when the simulation is garbage-collected; :meth:`save` copies it anywhere.

    The run advances on the scene's output grid (``[output] every`` and the snapshot ``times``): :meth:`step`
    reaches the next output sample, :meth:`integrate` every sample up to a time. The GIL is released while it
    integrates; Ctrl-C (``KeyboardInterrupt``) is honoured between samples (every 0.2 s of work at most, or at the
    end of a longer sample interval) and leaves a checkpoint in the run directory, from which :meth:`from_run` or
    ``rubblepile resume DIR`` continues it.
    """

    def __init__(self, inner: "_rubblepile.Simulation") -> None:
        self._inner = inner
        # The summary at close(), so that the numbers stay readable after a `with` block.
        self._closed_summary: Optional[Dict[str, Any]] = None

    # --- construction -------------------------------------------------------------------------------------------
    @classmethod
    def from_scene(
        cls,
        scene: Union[PathLike, Dict[str, Any], str],
        out: Optional[PathLike] = None,
        *,
        force: bool = False,
        checkpoint_every: Optional[float] = None,
        checkpoint_every_sim: Optional[float] = None,
        max_steps: Optional[int] = None,
        max_wall_seconds: Optional[float] = None,
    ) -> "Simulation":
        """Starts a fresh run of ``scene``, writing into the run directory ``out``.

        ``scene``: the path of a scene file (``str`` or ``os.PathLike``; relative input files resolve against its
        directory), a ``dict`` of the scene's tables (as ``tomllib.load`` gives them), or TOML text. The engine is
        the scene's ``scene.kind``.

        ``out``: the run directory (created; refused when it holds files unless ``force``); ``None``: a temporary
        one. ``checkpoint_every``: wall-clock seconds between checkpoints (default 600, as the command line);
        ``checkpoint_every_sim``: simulated seconds between checkpoints (0: at every sample); ``max_steps``,
        ``max_wall_seconds``: the run's budget (over the scene's ``[run]`` table).

        Raises :class:`SceneError` with the command line's one-line message (naming the field) when the scene is
        invalid or ``out`` cannot be used. Scene warnings are issued as Python warnings.
        """
        if isinstance(scene, os.PathLike):
            scene = os.fspath(scene)
        if out is not None:
            out = os.fspath(out)
        return cls(_rubblepile.Simulation.from_scene(
            scene, out, force=force, checkpoint_every=checkpoint_every,
            checkpoint_every_sim=checkpoint_every_sim, max_steps=max_steps, max_wall_seconds=max_wall_seconds))

    @classmethod
    def from_run(
        cls,
        dir: PathLike,
        *,
        checkpoint_every: Optional[float] = None,
        checkpoint_every_sim: Optional[float] = None,
        max_steps: Optional[int] = None,
        max_wall_seconds: Optional[float] = None,
    ) -> "Simulation":
        """Continues the run in ``dir`` from its ``checkpoint.json``, in place, as ``rubblepile resume DIR`` does:
        the finished run is bit for bit the uninterrupted one (wall-clock columns aside).

        Raises :class:`SceneError` (no checkpoint, already completed, a corrupt or mismatched directory).
        """
        return cls(_rubblepile.Simulation.from_run(
            os.fspath(dir), checkpoint_every=checkpoint_every, checkpoint_every_sim=checkpoint_every_sim,
            max_steps=max_steps, max_wall_seconds=max_wall_seconds))

    # --- advancing ------------------------------------------------------------------------------------------------
    def integrate(self, t: Optional[float] = None) -> float:
        """Advances through every output sample at or before ``t`` (s; default: the scene's ``t_end``, completing
        the run and writing its ``summary.json``) and returns the time reached (s): the last such sample's.

        Raises :class:`RunFailed` when the engine fails (the last good state and the summary are written),
        :class:`RunStopped` when the budget runs out (a checkpoint is written), ``ValueError`` for ``t`` past
        ``t_end``, ``KeyboardInterrupt`` on Ctrl-C (a checkpoint is written).
        """
        return self._inner.integrate(t)

    def step(self) -> float:
        """Advances to the next output sample and returns its time (s). Raises as :meth:`integrate`; after the
        last sample, :class:`SceneError`."""
        return self._inner.step()

    def checkpoint(self) -> None:
        """Writes ``checkpoint.json`` into the run directory now (the state at the last sample reached), so that
        the command line or :meth:`from_run` can continue the run from here."""
        self._inner.checkpoint()

    def save(self, dir: PathLike, *, force: bool = False) -> None:
        """Writes the run so far as an ordinary run directory ``dir`` (refused when it holds files unless
        ``force``): a checkpoint of the state now (unless the run completed or has not reached its first sample),
        then a copy of the run directory. ``rubblepile resume``, ``render``, ``analyze`` and :meth:`from_run` read
        it."""
        self._inner.save(os.fspath(dir), force=force)

    def close(self) -> None:
        """Ends the session: releases the run directory's lock (the files stay). The summary and its errors stay
        readable; further calls that need the run raise :class:`SceneError`."""
        if self._closed_summary is None:
            try:
                self._closed_summary = self.summary()
            except RubblepileError:
                pass
        self._inner.close()

    def __enter__(self) -> "Simulation":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # --- where it is --------------------------------------------------------------------------------------------
    @property
    def t(self) -> float:
        """Simulated time now (s)."""
        return self._inner.t

    @property
    def t_end(self) -> float:
        """The scene's end time (s)."""
        return self._inner.t_end

    @property
    def done(self) -> bool:
        """Whether the run has ended: completed (its last sample reached, ``summary.json`` written), failed or
        stopped by its budget; nothing more to advance."""
        return self._inner.done

    @property
    def kind(self) -> str:
        """The engine: ``"ellipsoids"``, ``"soft-spheres"`` or ``"hard-spheres"``."""
        return self._inner.kind

    @property
    def out_dir(self) -> str:
        """The run directory being written."""
        return self._inner.out_dir

    @property
    def sample_times(self) -> np.ndarray:
        """Times of every output sample of the run (s)."""
        return self._inner.sample_times

    @property
    def samples_done(self) -> int:
        """Output samples reached so far."""
        return self._inner.samples_done

    # --- the summary's numbers -------------------------------------------------------------------------------------
    def summary(self) -> Dict[str, Any]:
        """The run's summary as ``summary.json`` holds it (the engine's fields): the file itself once the run
        ended with one (completed or failed), else computed now, its ``status`` ``"running"`` (or ``"stopped"``
        after its budget ran out)."""
        if self._closed_summary is not None:
            return dict(self._closed_summary)
        written = os.path.join(self.out_dir, "summary.json")
        if self.done and os.path.isfile(written):
            # As written when the run ended (its wall time stopped then).
            with open(written) as f:
                return json.load(f)
        s = json.loads(self._inner._summary_json())
        if "status" in s:
            s["status"] = "stopped" if self.done else "running"
        return s

    @property
    def energy_error(self) -> float:
        """Relative energy error so far (``energy_error`` of the summary; dimensionless)."""
        return float(self.summary()["energy_error"])

    @property
    def momentum_error(self) -> Optional[float]:
        """Relative linear-momentum error so far (``linear_momentum_error`` or ``momentum_error`` of the summary)."""
        s = self.summary()
        v = s.get("linear_momentum_error", s.get("momentum_error"))
        return None if v is None else float(v)

    @property
    def angular_momentum_error(self) -> Optional[float]:
        """Relative angular-momentum error so far (``None`` for engines that do not track it: hard spheres)."""
        v = self.summary().get("angular_momentum_error")
        return None if v is None else float(v)

    @property
    def wall_seconds(self) -> float:
        """Wall-clock seconds of the run so far (s), pauses between calls included (the run's ``wall_seconds``)."""
        if self._closed_summary is not None or self.done:
            s = self.summary()
            if "wall_seconds" in s and s.get("status") != "stopped":
                return float(s["wall_seconds"])
        return self._inner.wall_seconds

    # --- the state ----------------------------------------------------------------------------------------------
    def state(self) -> Dict[str, np.ndarray]:
        """The particles now, as NumPy arrays (fresh copies), one row per particle in scene order:

        - ``ids`` (n,): index in the scene; ``masses`` (n,): kg;
        - ``positions``, ``velocities`` (n, 3): m, m/s (world frame);
        - ``angular_velocities`` (n, 3): spin in the world frame (rad/s);
        - ellipsoids: ``quaternions`` (n, 4): attitude (alpha, beta, gamma, delta), scalar last, as in scene files;
          ``spins_body`` (n, 3): spin about the principal axes (rad/s); ``semi_axes`` (n, 3): A >= B >= C (m);
        - spheres: ``radii`` (n,): m.
        """
        return dict(self._inner._state())

    def set_state(self, **arrays: Any) -> None:
        """Sets the state of a run (any engine) between two samples; the run continues from it.
        Keywords, each an array of one row per particle in scene order (those not given keep their values):

        - ellipsoids: ``positions`` (n, 3; m), ``velocities`` (n, 3; m/s), ``quaternions`` (n, 4; scalar last,
          normalised here), and one of ``angular_velocities`` (n, 3; rad/s, world frame) or ``spins_body`` (n, 3;
          rad/s, principal axes). Masses and semi-axes are the scene's.
        - spheres: ``positions`` (n, 3; m), ``velocities`` (n, 3; m/s), ``angular_velocities`` (n, 3; rad/s,
          world frame). Masses and radii are the scene's. Soft spheres: the forces and torques the next step starts
          from are evaluated again at the new state (the springs of contacts that still touch are kept, the
          neighbour list rebuilt); with ``[gravity] interval_steps > 1`` the state can be set only on a self-gravity
          block boundary. Hard spheres: the rows are the particles still in the run (as :meth:`state`); the
          neighbour list, the pair certificates and the predicted collisions are rebuilt from the new state; a
          particle stuck to a wall keeps its state; new positions must not overlap.

        The conserved quantities are still measured against t = 0, so a change of energy counts in
        :attr:`energy_error`. :meth:`save` (or a checkpoint) then holds the new state. Raises :class:`SceneError`
        for a wrong shape, a non-finite value, attitudes of a run that does not integrate them, or a changed state of
        a hard sphere stuck to a wall.
        """
        state = {k: np.ascontiguousarray(v, dtype=np.float64) for k, v in arrays.items()}
        self._inner._set_state(state)

    @property
    def ids(self) -> np.ndarray:
        """Index of each particle in the scene."""
        return self.state()["ids"]

    @property
    def masses(self) -> np.ndarray:
        """Masses (kg), shape (n,)."""
        return self.state()["masses"]

    @property
    def positions(self) -> np.ndarray:
        """Centres (m), shape (n, 3)."""
        return self.state()["positions"]

    @positions.setter
    def positions(self, value: np.ndarray) -> None:
        self.set_state(positions=value)

    @property
    def velocities(self) -> np.ndarray:
        """Velocities of the centres (m/s), shape (n, 3)."""
        return self.state()["velocities"]

    @velocities.setter
    def velocities(self, value: np.ndarray) -> None:
        self.set_state(velocities=value)

    @property
    def angular_velocities(self) -> np.ndarray:
        """Spins in the world frame (rad/s), shape (n, 3)."""
        return self.state()["angular_velocities"]

    @angular_velocities.setter
    def angular_velocities(self, value: np.ndarray) -> None:
        self.set_state(angular_velocities=value)

    @property
    def quaternions(self) -> np.ndarray:
        """Attitudes (alpha, beta, gamma, delta; scalar last), shape (n, 4); ellipsoids only."""
        return self._only("quaternions")

    @quaternions.setter
    def quaternions(self, value: np.ndarray) -> None:
        self.set_state(quaternions=value)

    @property
    def semi_axes(self) -> np.ndarray:
        """Semi-axes A >= B >= C (m), shape (n, 3); ellipsoids only."""
        return self._only("semi_axes")

    @property
    def radii(self) -> np.ndarray:
        """Radii (m), shape (n,); spheres only."""
        return self._only("radii")

    def _only(self, name: str) -> np.ndarray:
        s = self.state()
        if name not in s:
            raise AttributeError(f"{name}: not a state array of a {self.kind} run")
        return s[name]

    def __repr__(self) -> str:
        try:
            return f"<rubblepile.Simulation {self.kind} t={self.t} s of {self.t_end} s in {self.out_dir}>"
        except RubblepileError:
            return f"<rubblepile.Simulation (closed) in {self._inner.out_dir}>"


def impact(
    target: PathLike,
    out: Optional[PathLike] = None,
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
    snapshots: Optional[list] = None,
    snapshot_every: Optional[float] = None,
    every: float = 10.0,
    force: bool = False,
    checkpoint_every: Optional[float] = None,
    checkpoint_every_sim: Optional[float] = None,
    impact_parameter_m: Optional[float] = None,
    impact_parameter_frac: Optional[float] = None,
    impact_angle_deg: Optional[float] = None,
    aim_azimuth_deg: Optional[float] = None,
    projectile_spin_rad_s: Optional[list] = None,
    projectile_attitude: Optional[list] = None,
    run: bool = True,
) -> Simulation:
    """An impact of a projectile on a rubble-pile target (Roig03), as ``rubblepile impact`` sets it up: the run
    directory ``out`` (``None``: a temporary one) gets ``initial_bodies.csv``, ``impact.json`` and ``scene.toml``,
    then the run's outputs. Returns the :class:`Simulation`, integrated to ``t_end`` when ``run`` (else at t = 0,
    to advance with :meth:`Simulation.integrate`).

    Units are SI (unlike the command line's km and km/s): ``target``: a bodies file (e.g. ``targets/N30_T4.csv``);
    ``projectile``: preset P1, P2 or P3 (Roig03 Table 2), or ``projectile_radius`` (m, equivalent radius);
    ``speed`` (m/s); ``angle``: between the trajectory and the target's spin axis (degrees, 0-180); ``seed``: the
    projectile's attitude; ``contact_time``: when the surfaces first touch (s); ``t_end`` (s); ``rtol``: tolerance
    (default 1e-6 for Bulirsch-Stoer, 1e-8 for dop853/dopri5); ``method``: ``bulirsch-stoer``, ``dop853`` or
    ``dopri5``; ``f0``: dissipation coefficient F0 (s m^-2); ``beta``: Roig03 Eq. 14; ``inertia``: ``gaussian``
    or ``uniform``; ``kappa_reading``: ``printed``, ``impactor`` or ``reduced``; ``snapshots`` (s) or
    ``snapshot_every`` (s); ``every``: time-series cadence (s). Off-centre aim (at most one): ``impact_parameter_m``
    (b, m), ``impact_parameter_frac`` (b over the target's radius) or ``impact_angle_deg`` (θ to the surface normal
    at the aim point), with ``aim_azimuth_deg`` (ψ); ``projectile_spin_rad_s`` ([x, y, z], rad/s) and
    ``projectile_attitude`` (quaternion, scalar last), as ``rubblepile impact`` (README, *Impact experiments*).

    Raises :class:`SceneError` naming the argument (e.g. ``angle_deg: ...``) for a value out of range.
    """
    inner = _rubblepile.impact(
        os.fspath(target), None if out is None else os.fspath(out), projectile=projectile,
        projectile_radius=projectile_radius, speed=speed, angle=angle, seed=seed, contact_time=contact_time,
        t_end=t_end, rtol=rtol, method=method, f0=f0, beta=beta, inertia=inertia, kappa_reading=kappa_reading,
        snapshots=snapshots, snapshot_every=snapshot_every, every=every, force=force,
        checkpoint_every=checkpoint_every, checkpoint_every_sim=checkpoint_every_sim,
        impact_parameter_m=impact_parameter_m, impact_parameter_frac=impact_parameter_frac,
        impact_angle_deg=impact_angle_deg, aim_azimuth_deg=aim_azimuth_deg,
        projectile_spin_rad_s=projectile_spin_rad_s, projectile_attitude=projectile_attitude)
    sim = Simulation(inner)
    if run:
        sim.integrate()
    return sim


def analyze(dir: PathLike, at: Optional[float] = None, *, force: bool = False) -> Dict[str, Any]:
    """Analyses a finished run as ``rubblepile analyze DIR [--at-s T]`` does, writing ``DIR/analysis/``.

    An impact run (one with ``impact.json``) is analysed at ``at`` (s; default 400, or the run's end when sooner): fragments, energy partition,
    ejection and spin fits (Roig03 Sec. 4), clumps. Any other run: the clumps of the snapshot at ``at`` (default the
    last). Returns ``analysis.json`` as a dict (e.g. ``largest_remnant`` with its ``mass_kg``, ``mass_fraction``, ``n_members``, ``period_h``), plus ``lines``
    (the command line's summary lines) and, for an impact run, ``fragments`` (``analysis/fragments.csv``, column
    name -> array). Raises :class:`SceneError` (no such snapshot, an analysis already there without ``force``, ...).
    """
    text, lines = _rubblepile.analyze(os.fspath(dir), at, force=force)
    out = json.loads(text)
    out["lines"] = list(lines)
    frag = os.path.join(os.fspath(dir), "analysis", "fragments.csv")
    if os.path.isfile(frag):
        from .runs import _read_csv

        out["fragments"] = _read_csv(frag)
    return out


def build_target(
    fragments: int,
    period_hours: float,
    out: PathLike,
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
) -> Dict[str, Any]:
    """Builds a rubble-pile target as ``rubblepile target build`` does: ``fragments`` ellipsoids (30, 100 and 200
    take Roig03 Table 1's radii; any other number needs ``r_largest_km`` and ``r_smallest_km``, km) relaxed under
    self-gravity into a pile spinning with period ``period_hours`` (h). Writes the bodies file ``out`` (``.csv``,
    for :func:`impact`'s ``target``) and its report beside it (``.json``), which it returns as a dict.
    ``total_mass`` (kg), ``f0`` (s m^-2, dissipation while relaxing), ``rigidity`` (dimensionless, in (0, 1)).

    Raises :class:`SceneError` naming the argument for a bad value, or when ``out`` exists (unless ``force``).
    """
    text = _rubblepile.build_target(
        fragments, period_hours, os.fspath(out), seed=seed, r_largest_km=r_largest_km, r_smallest_km=r_smallest_km,
        total_mass=total_mass, f0=f0, rigidity=rigidity, drop_detached=drop_detached, kappa_reading=kappa_reading,
        force=force)
    return json.loads(text)


def build_aggregate(
    model: str,
    shape: str,
    out: PathLike,
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
) -> Dict[str, Any]:
    """Builds a soft-sphere aggregate for spin-up studies as ``rubblepile aggregate build`` does (Zhang17 Table 2):
    ``model`` hcp, rcp, rcpc, pp1, pp2 or ppc, carved to ``shape`` (``sphere:R``, ``ellipsoid:A,B,C``, ``top[:D_EQ]``,
    ``didymos[:LX,LY,LZ,D_EQ]``, ``obj:PATH``; m). Exactly one of ``particles`` (about this many grains), ``radius``
    (m, monodisperse) or ``radius_range`` ((rmin, rmax), m, dN/dr ~ r^-3). ``bulk_density`` (kg/m^3),
    ``core_radius`` (m, rcpc and ppc), ``lattice_orientation`` (perpendicular, parallel, tilt:DEG or random[:SEED]).
    Writes the particle file ``out`` (``.csv``) and its report beside it (``.json``), which it returns as a dict.

    Raises :class:`SceneError` naming the argument for a bad value, or when ``out`` exists (unless ``force``).
    """
    text = _rubblepile.build_aggregate(
        model, shape, os.fspath(out), particles=particles, radius=radius, radius_range=radius_range,
        bulk_density=bulk_density, core_radius=core_radius, seed=seed, lattice_orientation=lattice_orientation,
        shake_periods=shake_periods, gravity_interval=gravity_interval, obj_scale=obj_scale, force=force)
    return json.loads(text)


def flyby(
    target: PathLike,
    out: PathLike,
    *,
    q_m: float,
    v_inf_km_s: float = 5.8,
    radius_m: Optional[float] = None,
    period_hours: Optional[float] = None,
    planet_mass: float = 5.9722e24,
    planet_radius_m: float = 6.371e6,
    planet_j2: Optional[float] = None,
    planet_pole: Optional[list] = None,
    orientation_deg: Optional[list] = None,
    start_q: float = 10.0,
    kappa: Optional[float] = None,
    f0: Optional[float] = None,
    rtol: float = 1e-6,
    snapshots: int = 9,
    force: bool = False,
    run: bool = True,
    control: bool = True,
    settle_to_principal: bool = False,
    settle_max_hours: Optional[float] = None,
) -> Dict[str, Any]:
    """A tidal flyby of a rubble pile past a planet, as ``rubblepile flyby`` runs it: the pile of ``target`` (a
    bodies file; rescaled to ``radius_m`` (m) and re-spun to ``period_hours`` (h) when given, then settled) on a
    hyperbolic orbit of perigee ``q_m`` (m from the planet's centre) and speed at infinity ``v_inf_km_s`` (km/s, as
    the command line's flag) past a planet of ``planet_mass`` (kg; 0: a control without tide) and
    ``planet_radius_m`` (m), from and to ``start_q`` perigee distances; then, unless ``control=False``, the same
    run without the planet in ``out/control``; then the analysis (``out/analysis/flyby.json``).

    Returns ``{"lines": [the command line's lines], "analysis": flyby.json as a dict or None}``. With
    ``run=False`` only the run directory is written. Raises :class:`SceneError` naming the argument.
    """
    lines = _rubblepile.flyby(
        os.fspath(target), os.fspath(out), q_m=q_m, v_inf_km_s=v_inf_km_s, radius_m=radius_m,
        period_hours=period_hours, planet_mass=planet_mass, planet_radius_m=planet_radius_m, planet_j2=planet_j2,
        planet_pole=planet_pole, orientation_deg=orientation_deg, start_q=start_q, kappa=kappa, f0=f0, rtol=rtol,
        snapshots=snapshots, force=force, run=run, control=control, settle_to_principal=settle_to_principal,
        settle_max_hours=settle_max_hours)
    path = os.path.join(os.fspath(out), "analysis", "flyby.json")
    analysis = None
    if os.path.isfile(path):
        with open(path) as f:
            analysis = json.load(f)
    return {"lines": list(lines), "analysis": analysis}


# The columns of campaign.csv, in its order (the per-run results :func:`campaign` returns).
_CAMPAIGN_COLUMNS = ("run", "target", "projectile", "angle_deg", "seed", "q_erg_per_g", "status", "wall_seconds",
                     "final_time", "steps_accepted", "rhs_evaluations", "energy_error", "linear_momentum_error",
                     "angular_momentum_error")


def campaign(
    file: PathLike,
    out: Optional[PathLike] = None,
    *,
    parallel: Optional[int] = None,
    threads_per_run: Optional[int] = None,
    checkpoint_every: Optional[float] = None,
    checkpoint_every_sim: Optional[float] = None,
    max_steps: Optional[int] = None,
    max_wall_seconds: Optional[float] = None,
) -> Dict[str, Any]:
    """Runs an impact campaign as ``rubblepile campaign FILE [--out OUT]`` does: the grid of the campaign file
    (targets x projectiles x angles x seeds, Roig03 Sec. 3), ``parallel`` runs at once (default the file's
    ``campaign.parallel``) on this process's threads, one run directory per grid point under the campaign
    directory ``out`` (default the file's ``campaign.out``), and ``campaign.csv``. As the command line, completed
    runs are skipped and checkpointed ones resumed. ``threads_per_run``: threads of each run's pool (default this
    process's cores shared among the runs at once); ``checkpoint_every`` (wall-clock s), ``checkpoint_every_sim``
    (simulated s), ``max_steps``, ``max_wall_seconds`` (s): every run's options, as the command line's flags.

    Returns a dict:

    - ``runs``: the per-run results, one entry per grid point in grid order (``campaign.csv``'s rows), as column
      name -> NumPy array: ``run`` (name), ``target`` (file stem), ``projectile``, ``angle_deg`` (degrees),
      ``seed``, ``q_erg_per_g`` (specific impact energy, erg/g), ``status`` (``completed``, ``failed: <cause>``,
      ``pending``), ``wall_seconds`` (s), ``final_time`` (s), ``steps_accepted``, ``rhs_evaluations``,
      ``energy_error``, ``linear_momentum_error``, ``angular_momentum_error`` (relative; NaN where the run has no
      summary), plus ``action`` (``started``, ``resumed``, ``skipped``, ``conflict``), ``completed`` (bool),
      ``stopped`` (bool) and ``dir`` (each run directory, readable with :func:`read_run` and :func:`analyze`);
    - ``line``: the command line's closing line; ``out``: the campaign directory;
    - ``problem``: ``None``, or the command line's error message when runs failed or stopped (the command line
      exits 1 or 3 then; here the results are returned all the same).

    Raises :class:`SceneError` naming the field for a bad campaign file (the command line's exit code 2).
    """
    line, problem, out_dir, rows = _rubblepile.campaign(
        os.fspath(file), None if out is None else os.fspath(out), parallel=parallel,
        threads_per_run=threads_per_run, checkpoint_every=checkpoint_every,
        checkpoint_every_sim=checkpoint_every_sim, max_steps=max_steps, max_wall_seconds=max_wall_seconds)
    columns = _CAMPAIGN_COLUMNS + ("action", "completed", "stopped", "dir")
    runs: Dict[str, np.ndarray] = {}
    for name in columns:
        cells = [r[name] for r in rows]
        if name in ("seed", "steps_accepted", "rhs_evaluations"):
            runs[name] = np.array([-1 if c is None else c for c in cells], dtype=np.int64)
        elif name in ("completed", "stopped"):
            runs[name] = np.array(cells, dtype=bool)
        elif name in ("run", "target", "projectile", "status", "action", "dir"):
            runs[name] = np.array(cells, dtype=object)
        else:
            runs[name] = np.array([np.nan if c is None else c for c in cells], dtype=np.float64)
    return {"runs": runs, "line": line, "out": out_dir,
            "problem": None if problem is None else problem[0]}


def spinup(
    scene: Union[PathLike, Dict[str, Any], str],
    out: Optional[PathLike] = None,
    *,
    force: bool = False,
    checkpoint_every: Optional[float] = None,
    checkpoint_every_sim: Optional[float] = None,
    max_steps: Optional[int] = None,
    max_wall_seconds: Optional[float] = None,
) -> Dict[str, Any]:
    """Runs a spin-up (Zhang17 Sec. 2.3.4) as ``rubblepile run SCENE --out OUT`` does: a soft-sphere ``scene``
    (path, dict or TOML text, as :meth:`Simulation.from_scene`) with a ``[spinup]`` table, whose central body is
    spun along the period path T_start -> T_inter -> T_final (h) and then held, integrated to its ``t_end``. The run
    directory ``out`` (``None``: a temporary one, removed when the returned simulation is collected) gets the
    command line's files, ``spinup.csv`` among them.

    Returns a dict: ``spinup``: ``spinup.csv`` as column name -> NumPy array, one row per output sample: ``t``
    (s), ``path_period_h`` and ``period_h`` (the path's and the body's spin period, h), ``forcing`` (1 while
    forced), ``body_particles``, ``body_mass_fraction``, the body's semi-axes ``a``, ``b``, ``c`` (m) and their
    ratios, ``packing_fraction``, ``coordination_number``, ``theta_max_deg`` (the largest mobilised friction
    angle of its RVEs, degrees), ...; ``summary``: ``summary.json`` as a dict; ``dir``: the run directory;
    ``simulation``: the finished :class:`Simulation`.

    Raises :class:`SceneError` when the scene is not a soft-sphere scene with a ``[spinup]`` table, and as
    :meth:`Simulation.integrate`.
    """
    sim = Simulation.from_scene(scene, out, force=force, checkpoint_every=checkpoint_every,
                                checkpoint_every_sim=checkpoint_every_sim, max_steps=max_steps,
                                max_wall_seconds=max_wall_seconds)
    path = os.path.join(sim.out_dir, "spinup.csv")
    kind = sim.kind
    if kind != "soft-spheres" or not os.path.isfile(path):
        sim.close()
        raise SceneError(f"spinup: the scene is a {kind} scene without a [spinup] table (need a soft-spheres "
                         "scene with one)")
    sim.integrate()
    from .runs import _read_csv

    return {"spinup": _read_csv(path), "summary": sim.summary(), "dir": sim.out_dir, "simulation": sim}


def critical_search(
    scene: PathLike,
    out: PathLike,
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
) -> Dict[str, Any]:
    """Searches the third critical spin limit T_c,3 (Zhang17 Sec. 3.3.3) as ``rubblepile spinup critical`` does:
    for T_final = ``from_hours``, ``from_hours + step_hours``, ... up to ``to_hours`` (h) a hold run ``out/T<X>``
    spins the soft-sphere ``scene`` (with a ``[spinup]`` table whose ``t_end`` leaves a hold after ``t_final``) up
    to T_final and holds it; each hold is judged by the three creep criteria, and T_c,3 under a criterion is its
    first stable T_final. ``branch``: the holds branch off one run of the path (``out/base``), each ``hold``
    seconds long (s; default the scene's ``t_end - t_final``); ``criterion``: ``paper``, ``paper-tolerance`` or
    ``ours``, the one behind the top-level ``t_c3_hours``; ``significance`` (standard errors),
    ``coordination_tolerance`` (contacts per particle), ``judge_window`` (s), ``all_holds``, ``parallel`` (holds at
    once), ``threads_per_hold``, ``finish_released``: as the command line's flags. Writes ``out/critical.json``
    and ``out/critical.csv`` (refused when ``critical.json`` exists, unless ``force``).

    Returns a dict: ``t_c3_hours`` and ``friction_angle_deg`` (h, degrees; ``None`` where no hold is stable) of the
    selected criterion, ``criterion`` (its name); ``by_criterion``: for each of ``paper``, ``paper-tolerance``,
    ``ours`` a dict of ``t_c3_hours``, ``friction_angle_deg`` and ``set_aside_hours``; ``holds``: the holds as rows
    (``critical.csv``: column name -> NumPy array, one entry per hold by increasing T_final: ``t_final_h`` (h),
    ``hold_s`` (s), ``released``, ``theta_max_deg`` (degrees), the drifts, the rates and their standard errors
    per 1000 s, and ``<criterion>_stable`` / ``<criterion>_drifting`` per criterion); ``runs``: the holds as
    ``critical.json`` holds them (dicts, with each run's ``dir``); ``lines``: the command line's lines.

    Raises :class:`SceneError` for bad options or a scene without a usable ``[spinup]`` table,
    :class:`RubblepileError` when a hold fails.
    """
    lines = _rubblepile.critical_search(
        os.fspath(scene), os.fspath(out), from_hours=from_hours, to_hours=to_hours, step_hours=step_hours,
        force=force, branch=branch, criterion=criterion, significance=significance,
        coordination_tolerance=coordination_tolerance, hold=hold, judge_window=judge_window, all_holds=all_holds,
        parallel=parallel, threads_per_hold=threads_per_hold, finish_released=finish_released)
    from .runs import _read_csv

    with open(os.path.join(os.fspath(out), "critical.json")) as f:
        result = json.load(f)
    by_criterion = {}
    for key, name in (("paper", "paper"), ("paper_tolerance", "paper-tolerance"), ("ours", "ours")):
        r = result[key]
        by_criterion[name] = {"t_c3_hours": r.get("t_c3_hours"), "friction_angle_deg": r.get("friction_angle_deg"),
                              "set_aside_hours": list(r.get("set_aside_hours", []))}
    return {
        "t_c3_hours": result.get("t_c3_hours"),
        "friction_angle_deg": result.get("friction_angle_deg"),
        "criterion": criterion,
        "by_criterion": by_criterion,
        "holds": _read_csv(os.path.join(os.fspath(out), "critical.csv")),
        "runs": result["runs"],
        "lines": list(lines),
    }
