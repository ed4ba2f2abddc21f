"""``kind: dynamics_work_precision``: integrators x dt = 2^-k on a scene with a reference.

Scenes: ``harmonic_oscillator`` / ``single_spring`` (node 0 pinned, node 1 of mass ``m`` on a spring
of stiffness ``k``, started ``amplitude`` below its equilibrium, optional gravity along -y): the
analytic solution ``y(t) = y_eq + (y0 - y_eq) cos(sqrt(k/m) t)`` is the reference. ``rope`` (``n``
nodes, first pinned, falling under gravity): a converged reference run by ``reference.integrator``
(default RK4) at ``reference.dt`` (default the smallest swept dt / 16), stated in the report.

Per run: error at the end time and the maximum over the trajectory (2-norm of all position
errors at the common times, multiples of the largest dt), relative energy drift and its maximum,
steps, wall time (minimum over repeats after a warm-up). A run that raises
:class:`~femkit.errors.InstabilityError` is recorded as unstable (step, time, reason), never a crash,
and left out of the fits. Orders are fitted over the asymptotic range only
(:func:`~femkit.study.fit.fit_asymptotic`: coarse dt dropped until the finest ones lie on a line);
the fit records the dt used, those dropped and the local slopes between consecutive dt.
"""

from __future__ import annotations

import warnings

import numpy as np

from ...errors import InstabilityError
from ...interrupt import active_flag
from ...progress import progress
from ..fit import fit_asymptotic
from ..timing import time_call


def build_scene(scene):
    """(system, x0, v0, exact) of a :class:`~femkit.study.dynamics_work_precision.spec.DynamicsScene`, with
    ``exact(times) -> (m, n, d)`` positions, or None for a scene without a closed form."""
    from ...dynamics import rope, single_spring
    from ...dynamics.forces import Gravity

    k, m, g = scene.k, scene.mass, scene.gravity
    if scene.analytic:
        sys_ = single_spring(k=k, m=m, rest=scene.rest, gravity=g or None)
        x0 = sys_.x0.copy()
        y_eq = x0[0, 1] - scene.rest - m * g / k
        y0 = y_eq - scene.amplitude
        x0[1, 1] = y0
        w = np.sqrt(k / m)

        def exact(t):
            t = np.asarray(t, float)
            out = np.broadcast_to(x0, (t.size,) + x0.shape).copy()
            out[:, 1, 1] = y_eq + (y0 - y_eq) * np.cos(w * t)
            return out

        return sys_, x0, np.zeros_like(x0), exact
    n = scene.n
    forces = [Gravity(g)] if g else []
    sys_ = rope(n, scene.rest * (n - 1), k=k, mass=m, pinned="first", forces=forces)
    return sys_, sys_.x0.copy(), np.zeros_like(sys_.x0), None


def _simulate(system, name, opts, dt, t_end, x0, v0, every, limit):
    from ...dynamics.simulate import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the sweep crosses critical steps on purpose
        return simulate(system, name, dt, t_end, x0=x0, v0=v0, record_every=every,
                        energy_growth_limit=limit, **opts)


def run(study, *, progress_enabled=None) -> dict:
    d = study.spec
    scene = d.scene
    system, x0, v0, exact = build_scene(scene)
    t_end = scene.t_end
    dts = list(d.dts)
    dt_big = max(dts)
    ratios = [dt_big / dt for dt in dts]
    if not all(abs(r - round(r)) < 1e-9 for r in ratios) or abs(t_end / dt_big - round(t_end / dt_big)) > 1e-9:
        from ...errors import CaseFileError

        raise CaseFileError("dt: every dt must divide the largest one, and the largest must divide scene.t_end "
                            "(errors are compared at common times)")
    n_common = int(round(t_end / dt_big))
    t_common = np.arange(n_common + 1) * dt_big
    notes, tables, ref_error = [], {}, 0.0
    ref = d.reference
    if exact is not None and ref.analytic:
        ref_x = exact(t_common)
        notes.append(f"Reference: the analytic solution y(t) = y_eq + (y0 - y_eq) cos(sqrt(k/m) t), k = {scene.k:g}, "
                     f"m = {scene.mass:g}.")
    else:
        rname, rdt = ref.integrator, ref.dt
        every = max(1, int(round(dt_big / rdt)))
        rtraj, ref_error = _reference_run(system, rname, dt_big, every, t_end, x0, v0)
        ref_x = rtraj.x
        notes.append(f"Reference: a {rname} run at dt = {dt_big / every:.3g} ({every} steps per largest dt; "
                     f"{rtraj.steps} steps, {rtraj.wall_time:.2f} s); its own error estimate {ref_error:.3g} "
                     f"(max over the trajectory; Richardson against the same method at twice that dt).")
        tables["reference"] = [{"integrator": rname, "dt": dt_big / every, "steps": rtraj.steps,
                                "wall_time": rtraj.wall_time, "error_estimate": ref_error}]
    free = ~system.pinned
    records, energy_series = [], {}
    integrators = [(i.method, i.options, i.label) for i in study.integrators]
    if d.warmup:
        for name, opts, _ in integrators:
            try:
                _simulate(system, name, opts, dts[-1], min(t_end, 20 * dts[-1]), x0, v0, 1, np.inf)
            except InstabilityError:
                pass
    jobs = [(i, dt) for i in integrators for dt in dts]
    for (name, opts, label), dt in progress(jobs, total=len(jobs), desc=study.name, unit="run",
                                                enabled=progress_enabled, stop=active_flag(),
                                                costs=[t_end / dt for _, dt in jobs]):  # steps
        every = int(round(dt_big / dt))
        rec = {"integrator": label, "name": name, "dt": dt, "k": -np.log2(dt), "steps": int(round(t_end / dt))}
        try:
            timing = time_call(lambda: _simulate(system, name, opts, dt, t_end, x0, v0, every, d.energy_growth_limit),
                               repeats=d.repeats, warmup=0)
            traj = timing.value
            diff = (traj.x - ref_x)[:, free]
            err_t = np.sqrt(np.sum(diff.reshape(len(diff), -1) ** 2, axis=1))
            e = traj.energies["total"]
            rel = np.abs(e - e[0]) / traj.energy_scale
            rec.update(stable=True, error_end=float(err_t[-1]), error_max=float(err_t.max()),
                       energy_drift=float(traj.energy_drift), energy_drift_max=float(rel.max()),
                       wall_time=timing.min, wall_time_median=timing.median, omega_max=traj.omega_max,
                       dt_crit=traj.dt_crit, reason="")
            energy_series.setdefault(label, {})[dt] = (traj.times, rel)
        except InstabilityError as exc:
            rec.update(stable=False, error_end=None, error_max=None, energy_drift=exc.energy_ratio,
                       energy_drift_max=None, wall_time=None, wall_time_median=None,
                       omega_max=getattr(exc.partial, "omega_max", None), dt_crit=exc.dt_crit,
                       reason=f"{exc.reason or 'energy grew'} at step {exc.step} (t = {exc.time:.4g})")
        rec["h_omega"] = dt * rec["omega_max"] if rec.get("omega_max") else None
        records.append(rec)
    fits = []
    from ...dynamics.integrators import get_integrator

    # drop the round-off floor: errors below 1e-11 of the motion's scale no longer follow dt^p
    scale = float(np.abs(ref_x[:, free] - ref_x[0, free]).max()) or 1.0
    for name, opts, label in integrators:
        rows = [r for r in records if r["integrator"] == label and r["stable"] and r["error_end"]]
        # ... and runs within 10x of the reference's own error (the reference limits them, not dt)
        pts = [(r["dt"], r["error_max"]) for r in rows if r["error_max"] > max(1e-11 * scale, 10 * ref_error)]
        if len(pts) >= 2:
            a = fit_asymptotic(*np.array(pts).T)
            fits.append({"integrator": label, "error": "max over trajectory",
                         "declared_order": get_integrator(name, **opts).order, **a.fit.as_dict(), "fit": a.fit,
                         "dt_used": a.used.tolist(), "dt_dropped": a.dropped.tolist(),
                         "local_slopes": a.local_slopes.tolist(), "asymptotic": a.asymptotic,
                         "unstable_dt": [r["dt"] for r in records if r["integrator"] == label and not r["stable"]]})
    limited = [r for r in records if r["stable"] and r["error_max"] is not None and r["error_max"] <= 10 * ref_error]
    if limited:
        notes.append(f"The reference is not converged enough for {len(limited)} run(s): their errors lie within 10x "
                     f"of its own error estimate ({ref_error:.3g}), so they measure the reference and are left out "
                     f"of the fitted orders; give reference.dt smaller.")
    return {"records": records, "fits": fits, "notes": notes, "energy": energy_series, "dts": dts, "tables": tables}


def _reference_run(system, name, dt_big, every, t_end, x0, v0):
    """The reference trajectory at ``dt_big / every`` and its own error (max over the common times).

    The error is estimated by Richardson extrapolation against the same method at twice the step
    (``||x_h - x_2h|| / (2^p - 1)``; when ``every`` is odd, against half the step instead,
    ``||x_h - x_h/2|| 2^p / (2^p - 1)``). A reference that blows up is an input error.
    """
    from ...dynamics.integrators import get_integrator
    from ...errors import CaseFileError

    p = get_integrator(name).order
    free = ~system.pinned
    try:
        rtraj = _simulate(system, name, {}, dt_big / every, t_end, x0, v0, every, np.inf)
        if every % 2 == 0:
            other = _simulate(system, name, {}, 2 * dt_big / every, t_end, x0, v0, every // 2, np.inf)
            factor = 1.0 / (2**p - 1)
        else:
            other = _simulate(system, name, {}, dt_big / every / 2, t_end, x0, v0, 2 * every, np.inf)
            factor = 2**p / (2**p - 1)
    except InstabilityError as exc:
        raise CaseFileError(f"reference: the {name} reference run at dt = {dt_big / every:.3g} is unstable "
                            f"({exc.reason or 'energy grew'}); give a smaller reference.dt") from None
    diff = (other.x - rtraj.x)[:, free]
    err = float(np.sqrt(np.sum(diff.reshape(len(diff), -1) ** 2, axis=1)).max()) * factor
    if not np.isfinite(err):
        raise CaseFileError(f"reference: the {name} reference run at dt = {dt_big / every:.3g} is not finite; "
                            "give a smaller reference.dt")
    return rtraj, err
