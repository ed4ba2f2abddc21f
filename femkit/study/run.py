"""``run_study(study, output_dir=None) -> StudyResult``: run a sweep and write its report.

The report directory holds ``report.md``, ``report.html`` (figures embedded), ``figures/*.png``,
``runs.csv`` (one row per run), extra CSV tables per kind, and ``results.json`` with everything
(records, fitted rates, notes, the input fingerprint). It appears atomically: a failing study
leaves an earlier report untouched, and so does a study stopped by SIGINT/SIGTERM: the sweep and the
report run inside :func:`femkit.interrupt.raising`, so a signal stops them at once, wherever they are. :class:`StudyResult` carries the same data in memory.
"""

from __future__ import annotations

import os
import platform
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..kinds import KINDS
from ..interrupt import raising
from .cache import fingerprint
from .report import Report, staged_output, write_csv, write_json

__all__ = ["StudyResult", "run_study"]


@dataclass
class StudyResult:
    """What a study measured.

    Attributes
    ----------
    kind, name : str
    records : list of dict
        One dict per run (the rows of ``runs.csv``).
    fits : list of dict
        Fitted rates: ``slope``, ``intercept``, ``r2``, ``slope_stderr``, ``n`` and what was fitted.
    tables : dict of name -> list of dict
        Extra tables (e.g. ``nested`` for stop-at-discretisation-error, ``verdicts`` for stability).
    notes : list of str
    output_dir : Path or None
        Where the report was written.
    figures : list of str
        Figure paths relative to ``output_dir``.
    fingerprint : str
        SHA-256 of the inputs (see :mod:`femkit.study.cache`).
    """

    kind: str
    name: str
    records: list
    fits: list = field(default_factory=list)
    tables: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    output_dir: Path | None = None
    figures: list = field(default_factory=list)
    fingerprint: str = ""
    elapsed: float = 0.0

    def column(self, key: str, **where) -> np.ndarray:
        """Values of ``key`` over the records matching ``where`` (e.g. ``solver="cg"``)."""
        rows = [r for r in self.records if all(r.get(k) == v for k, v in where.items())]
        return np.array([np.nan if r.get(key) is None else r.get(key) for r in rows])

    def fit(self, **where) -> dict:
        """The single fit matching ``where`` (e.g. ``norm="L2", solver="direct"``)."""
        rows = [f for f in self.fits if all(f.get(k) == v for k, v in where.items())]
        if len(rows) != 1:
            raise KeyError(f"{len(rows)} fits match {where}")
        return rows[0]

    def plot(self, field: str | None = None, size: tuple[int, int] = (960, 720)):
        """The report's figure ``field`` (default: the first one the report shows) as a picture
        (``femkit[view]``: pyvista, imported only now); a notebook shows it inline, as
        ``femkit view OUTPUT_DIR`` draws it (docs/views.md).

        Returns
        -------
        femkit.view.core.view.View
            ``.screenshot(path)``, ``.show()``; ``.fields``: the figures' names.
        """
        from ..errors import InputError
        from ..view.core import view_of

        if self.output_dir is None:
            raise InputError(f"study {self.name!r} wrote no report, so no figure to draw: run it "
                             "with write=True")
        return view_of(self, field=field, size=size)

    def to_dict(self) -> dict:
        return {"kind": self.kind, "name": self.name, "records": self.records,
                "fits": [{k: v for k, v in f.items() if k != "fit"} for f in self.fits],
                "tables": self.tables, "notes": self.notes, "figures": self.figures,
                "fingerprint": self.fingerprint, "elapsed": self.elapsed}


def run_study(study, output_dir=None, *, progress: bool | None = None, write: bool = True) -> StudyResult:
    """Run ``study`` (a :class:`~femkit.study.load.Study`) and write its report.

    Parameters
    ----------
    study : Study
    output_dir : path, optional
        Report directory (default: ``study.default_output()``); replaced whole on success.
    progress : bool, optional
        Progress bar over the sweep (default: only when stderr is a terminal).
    write : bool
        False runs the sweep and returns the data without writing anything.
    """
    t0 = time.perf_counter()
    if write:  # a bad report location is refused before the sweep runs
        from ..io.atomic import EARLIER_REPORT, check_output_dir

        check_output_dir(output_dir if output_dir is not None else study.default_output(),
                         EARLIER_REPORT)
    kind = KINDS.get(study.kind, "kind")
    with raising(f"the {study.name} sweep"):  # a signal stops the current run at once
        data = kind.run(study, progress_enabled=progress)
    result = StudyResult(kind=study.kind, name=study.name, records=data["records"], fits=data.get("fits", []),
                         tables=data.get("tables", {}), notes=data.get("notes", []),
                         fingerprint=fingerprint(study.files, extra={"quick": study.quick, "data": study.data}))
    if "nested" in data and data["nested"]:
        result.tables["nested"] = data["nested"]
    result.elapsed = time.perf_counter() - t0
    if not write:
        return result
    out = Path(output_dir) if output_dir is not None else study.default_output()
    with raising("the report"), staged_output(out) as stage:  # refuses a non-report directory (never deletes user files)
        os.makedirs(stage / "figures", exist_ok=True)
        report = Report(study.title)
        report.paragraph(f"Study `{study.name}` ({study.kind}{', quick mode' if study.quick else ''}); "
                         f"{len(result.records)} runs in {result.elapsed:.1f} s on {platform.machine()} / "
                         f"Python {platform.python_version()}; BLAS threads: "
                         f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}. "
                         f"Input fingerprint `{result.fingerprint[:16]}`.")
        if study.spec.description:
            report.paragraph(study.spec.description)
        kind.report(report, study, result, data, stage)
        if result.notes:
            report.heading("Notes")
            for n in result.notes:
                report.paragraph(n)
        report.heading("Data files")
        report.paragraph("runs.csv (one row per run), " + ("fits.csv (every fitted rate), " if result.fits else "")
                         + "results.json (records, fits, tables, notes)"
                         + "".join(f", {k}.csv" for k in result.tables) + ".")
        result.figures = report.figures
        write_csv(stage / "runs.csv", result.records)
        if result.fits:
            write_csv(stage / "fits.csv", result.to_dict()["fits"])
        for name, rows in result.tables.items():
            write_csv(stage / f"{name}.csv", rows)
        write_json(stage / "results.json", result.to_dict())
        report.write(stage)
    result.output_dir = out.resolve()
    return result
