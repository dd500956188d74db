"""rockfrag.cli - the ``rockfrag`` command; subcommands are named after pipeline stages.

Input : command-line arguments. Output: files in the output folder (``reports/`` by default) and a
short summary on stdout. A user error (bad record, bad parameter) prints one line on stderr and
exits with status 2, without a traceback; files already written stay valid. Skipped records give
status 1; anything else (a bug) one line, a traceback log file in the output folder and status 3
(``EXIT_CODES``). A command holds the lock of its output folder (rockfrag.locking) while it runs.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import io
import os
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path

from rockfrag.errors import PipelineError
from rockfrag.locking import output_lock
from rockfrag.validation import did_you_mean
from rockfrag.version import __version__

EXIT_USER_ERROR = 2
EXIT_PARTIAL = 1


# ---------------------------------------------------------------- argument types (checked at parse time)

def _number_type(low, *, low_open=True, high=None, high_open=False, whole=False):
    """An argparse type: a (whole) number in a range, else a one-line usage error."""
    wanted = "a whole number" if whole else "a number"
    limits = [f"{'>' if low_open else '>='} {low:g}"] + ([f"{'<' if high_open else '<='} {high:g}"]
                                                         if high is not None else [])

    def convert(text):
        try:
            value = int(text) if whole else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {wanted}") from None
        too_low = value <= low if low_open else value < low
        too_high = high is not None and (value >= high if high_open else value > high)
        if too_low or too_high or value != value:
            raise argparse.ArgumentTypeError(f"{text} must be {' and '.join(limits)}")
        return value

    convert.__name__ = "whole number" if whole else "number"
    return convert


POSITIVE = _number_type(0)
POOL_SIZE = _number_type(1, low_open=False, whole=True)
GRID_SIZE = _number_type(2, low_open=False, whole=True)


def _name(text):
    if not text.strip():
        raise argparse.ArgumentTypeError("empty; name a record set, a record id, a folder or a file")
    return text


# ---------------------------------------------------------------- shared options, defined once

def _parent():
    return argparse.ArgumentParser(add_help=False)


def _study_option(positional=True):
    parent = _parent()
    if positional:
        parent.add_argument("study", nargs="?", type=Path, default=None,
                            help="study TOML file (default: the shipped pipeline/defaults.toml)")
    else:
        parent.add_argument("--study", type=Path, default=None, metavar="TOML",
                            help="study TOML file (default: the shipped pipeline/defaults.toml)")
    return parent


def _record_set_option():
    parent = _parent()
    parent.add_argument("--set", dest="record_set", action="append", type=_name, metavar="NAME",
                        help="record set (far-field, near-field-pulse, near-field-no-pulse, near-field, "
                             "peer-original, bolu, all), a record id, or a folder/file of your own records; "
                             "repeatable (default: the study's study.record_sets)")
    return parent


def _reading_options():
    parent = _parent()
    parent.add_argument("--units", default=None,
                        help="acceleration units of your own files that do not state them: g, m/s^2, cm/s^2, "
                             "gal (default: the study's study.units)")
    parent.add_argument("--dt", type=POSITIVE, default=None, metavar="SECONDS",
                        help="time step of one-column text records [s] (default: the study's study.dt)")
    parent.add_argument("--processing", type=Path, default=None, metavar="TOML",
                        help="processing recipe (default: the study's study.processing, else "
                             "pipeline/processing.toml)")
    return parent


def _output_option():
    parent = _parent()
    parent.add_argument("--output", type=Path, default=None, metavar="DIR",
                        help="output folder (default: the study's study.output, reports/)")
    parent.add_argument("--no-progress", action="store_true", help="hide progress bars")
    parent.add_argument("--force", action="store_true",
                        help="run a study whose blocks or soils look physically implausible (one warning each)")
    parent.add_argument("--wait", action="store_true",
                        help="if another rockfrag run is writing to the output folder, wait for it to finish "
                             "(default: stop with an error)")
    return parent


def _workers_option(scheduler):
    parent = _parent()
    parent.add_argument("--workers", type=POOL_SIZE, default=None, metavar="N",
                        help="worker processes (N >= 1; 1 runs in this process; default: all cores)")
    parent.add_argument("--serial", dest="workers", action="store_const", const=1,
                        help="same as --workers 1")
    if scheduler:
        parent.add_argument("--scheduler", default=None, metavar="local|ADDRESS",
                            help="run the study on dask: 'local' starts a LocalCluster of --workers processes, "
                                 "an address such as tcp://host:8786 uses a running cluster")
    return parent


# ---------------------------------------------------------------- from arguments to a study

def _study_config(args, applicability=None):
    """The study (file or shipped default) with the command-line options that override its keys.

    One rule for every command: an option left out takes the study's value (``--set``:
    study.record_sets, ``--output``: study.output, ``--processing``: study.processing, ``--units`` and
    ``--dt``: study.units and study.dt); without a study file, the shipped defaults.

    The study is loaded once per command (cached on ``args``: ``main`` asks for the output folder before the
    command runs), and each plausibility warning of ``--force`` is shown once however often it is loaded.
    """
    key = repr(sorted((applicability or {}).items()))
    cache = args.__dict__.setdefault("loaded_studies", {})
    if key not in cache:
        cache[key] = _load_study_once(args, applicability)
    return cache[key]


def _load_study_once(args, applicability):
    """``_study_config`` without its cache; repeats no plausibility warning an earlier load of ``args`` gave."""
    from rockfrag.config import load_study
    from rockfrag.plausibility import PlausibilityWarning

    study = {}
    if getattr(args, "record_set", None):
        study["record_sets"] = list(args.record_set)
    for option, key in (("processing", "processing"), ("units", "units"), ("dt", "dt")):
        value = getattr(args, option, None)
        if value is not None:
            study[key] = str(value) if isinstance(value, Path) else value
    overrides = {"study": study} if study else {}
    if getattr(args, "force", False):
        overrides["checks"] = {"plausibility": "warn"}
    if applicability:
        overrides["applicability"] = applicability
    shown = args.__dict__.setdefault("plausibility_warned", set())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PlausibilityWarning)
        config = load_study(args.study, overrides or None)
    for warning in caught:
        text = str(warning.message)
        if issubclass(warning.category, PlausibilityWarning) and text in shown:
            continue
        shown.add(text)
        warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
    return config, Path(args.output) if getattr(args, "output", None) else config.output


def _executor_options(args) -> dict:
    """run_study's executor arguments: a process pool of --workers, or dask with --scheduler."""
    scheduler = getattr(args, "scheduler", None)
    if scheduler is None:
        return {"workers": args.workers}
    if scheduler == "local":
        import os

        return {"dask_workers": args.workers or os.cpu_count()}
    if args.workers is not None:
        raise PipelineError(f"--workers {args.workers} with --scheduler {scheduler}: a running cluster has its "
                            "own workers; use --workers with --scheduler local or without --scheduler")
    from rockfrag.executors import check_scheduler

    check_scheduler(scheduler)  # whether or not cells remain to compute
    return {"scheduler": scheduler}


def _log(message):
    print(message, file=sys.stderr)


# ---------------------------------------------------------------- commands

def command_records(args) -> int:
    """``rockfrag records``: the records table (records.csv) and, with ``--plot``, a figure per record."""
    import pandas as pd

    from rockfrag.processing import load_recipe
    from rockfrag.records import load_records
    from rockfrag.records_report import TABLE_COLUMNS, records_stage

    config, output = _study_config(args)
    recipe = load_recipe(config.processing or None)
    records, failures = load_records(list(config.record_sets), units=config.record_units or None,
                                     dt=config.record_dt)
    for failure in failures:
        _log(f"rockfrag: skipped {failure}")
    if not records:
        raise PipelineError("no record could be read; nothing to do")
    unprocessed = []
    with output_lock(output):
        table, pngs = records_stage(records, recipe, output, plot=args.plot, progress=not args.no_progress,
                                    failures=unprocessed)
    for failure in unprocessed:
        _log(f"rockfrag: skipped {failure}")
    failures = [*failures, *unprocessed]
    if table.empty:
        raise PipelineError("no record could be processed; nothing to do")
    shown = table[["id", "event", "station", "component", *TABLE_COLUMNS]].rename(columns=TABLE_COLUMNS)
    with pd.option_context("display.max_rows", None, "display.width", 200, "display.max_colwidth", 28):
        print(shown.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"\nwrote {output / 'records.csv'} ({len(table)} records)")
    if pngs:
        print(f"wrote {len(pngs)} figures in {output / 'records'}/")
    flagged = table[table["qa_flags"].astype(bool)]
    if len(flagged):
        print(f"QA: {len(flagged)} record(s) flagged (kept): {', '.join(flagged['id'])}; see qa_flags")
    return EXIT_PARTIAL if failures else 0


def command_run(args) -> int:
    """``rockfrag run``: the study cube (cube.nc) and the showcase (showcase.nc); resumes from checkpoints."""
    from rockfrag.showcase import showcase_stage
    from rockfrag.study import run_study, study_records

    config, output = _study_config(args)
    loaded = study_records(config, log=_log)
    dataset, stats = run_study(config, output=output, progress=not args.no_progress, loaded=loaded,
                               **_executor_options(args))
    showcase_stage(config, output, loaded)
    runs = stats["runs_computed"]
    rate = f", {runs / stats['seconds']:.0f} runs/s" if runs else ""
    print(f"wrote {output / 'cube.nc'} ({stats['seconds']:.1f} s{rate}; "
          f"{stats['cells_reused']} of {stats['cells']} cells reused from checkpoints)")
    return EXIT_PARTIAL if stats["failures"] else 0


def command_fragility(args) -> int:
    """``rockfrag fragility``: the whole pipeline.

    Study cube, IDA, fragility and risk, applicability (``run_applicability``), report, and the answer table
    (``rockfrag.answer``; not with ``--quiet``).
    """
    import time

    import xarray as xr

    from rockfrag.fragility import fragility_stage
    from rockfrag.ida import ida_stage
    from rockfrag.report import report_stage
    from rockfrag.showcase import showcase_stage
    from rockfrag.study import run_study, study_records

    started = time.perf_counter()
    config, output = _study_config(args)
    from rockfrag.risk import study_hazard

    hazard = study_hazard(config)  # a hazard curve for another intensity measure fails here, before any run
    if hazard is not None and hazard.site is not None:
        print(f"hazard: {hazard.source}, {hazard.site.describe()}")
    executor = _executor_options(args)
    loaded = study_records(config, log=_log)
    cube, stats = run_study(config, output=output, progress=not args.no_progress, loaded=loaded, **executor)
    print(f"wrote {output / 'cube.nc'} ({stats['cells_reused']} of {stats['cells']} cells from checkpoints)")
    showcase_stage(config, output, loaded)
    ida = ida_stage(cube, output)
    print(f"wrote {output / 'ida.nc'}")
    if "capacity_scale_factor" in cube:  # measure ranking from the adaptive capacities (no solver runs)
        from rockfrag.efficiency import efficiency_stage

        efficiency_stage(cube, loaded.records, config, output)
        print(f"wrote {output / 'efficiency.nc'} and {output / 'efficiency.csv'}")
    fragility, risk = fragility_stage(cube, ida, config, output, progress=not args.no_progress)
    for name in ("fragility.nc", "fragility.csv", "fragility_pelicun.csv", "fragility_openquake.xml"):
        if (output / name).is_file():  # no OpenQuake file for a measure OpenQuake does not have
            print(f"wrote {output / name}")
    if run_applicability(args, config):
        from rockfrag.applicability import applicability_stage

        applicability = applicability_stage(config, output, workers=args.workers, progress=not args.no_progress,
                                            loaded=loaded)
    else:  # not None: the report would read an applicability.nc an earlier run left in the folder
        applicability = xr.Dataset()
        _log("rockfrag: the applicability sweep (where Housner's rigid base is good enough; minutes) was not run: "
             "for a study file it runs with --applicability or the study's [applicability] run = true")
    results_s = time.perf_counter() - started  # the run time the report states: one number, here and there
    pdf, pngs = report_stage(config, cube, ida, fragility, risk, output, results_s, applicability,
                             progress=not args.no_progress, workers=args.workers, run=stats)
    print(f"wrote {pdf}, {output / 'report.html'} and {len(pngs)} figure page images in {output / 'figures'}/")
    print(f"done in {time.perf_counter() - started:.0f} s (results in {results_s:.0f} s, as the report states; "
          f"the report in {time.perf_counter() - started - results_s:.0f} s)")
    if not args.quiet:
        from rockfrag.answer import answer_table
        from rockfrag.report import report_results
        from rockfrag.report.summary import terminal_verdicts

        print()
        print(answer_table(fragility, outputs=(pdf, output / "fragility.csv", output / "fragility.nc")))
        print()  # the verdicts in the report summary's words (one source: rockfrag.report.summary)
        print(terminal_verdicts(report_results(config, cube, ida, fragility, risk, output, results_s, applicability,
                                               stats)))
    return EXIT_PARTIAL if stats["failures"] else 0


def run_applicability(args, config) -> bool:
    """Whether ``rockfrag fragility`` runs the applicability sweep.

    ``--applicability``/``--no-applicability`` decide if given; else the study's ``[applicability] run``;
    else the sweep runs for the default study only (no study file), not for a user's study.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``fragility`` command line (``applicability``: True, False or None; ``study``).
    config : rockfrag.config.StudyConfig
        The loaded study.

    Returns
    -------
    bool
        True to run the sweep.
    """
    if args.applicability is not None:
        return bool(args.applicability)
    run = config.raw.get("applicability", {}).get("run")
    if run is not None:
        return bool(run)
    return args.study is None


def _ground_motion(args, config):
    from rockfrag.processing import load_recipe, process_record
    from rockfrag.records import load_records

    records, failures = load_records(args.record, units=config.record_units or None, dt=config.record_dt)
    if failures:
        raise failures[0]
    if len(records) != 1:
        raise PipelineError(f"--record {args.record!r} selects {len(records)} records; name exactly one")
    record = records[0] if args.raw else process_record(records[0], load_recipe(config.processing or None))
    return record, record.acceleration * args.scale


def _calibration_bed(args, config) -> dict:
    """``{"bed": ...}`` for a model with a bed (``--bed``, else the study's ``[solver] bed``), else ``{}``."""
    from rockfrag.models import BED_TYPES, get_model

    if args.bed is not None and args.bed not in BED_TYPES:
        raise PipelineError(f"--bed {args.bed!r} unknown{did_you_mean(args.bed, BED_TYPES)}; valid: "
                            f"{', '.join(BED_TYPES)}")
    if not get_model(args.model).uses_bed:
        if args.bed is not None:
            raise PipelineError(f"--bed {args.bed}: model {args.model!r} has no bed; --bed applies to winkler")
        return {}
    return {"bed": args.bed or config.bed}


def command_calibrate(args) -> int:
    """``rockfrag calibrate``: k and xi of the SSI model fitted to a reference history (eq. 17)."""
    from rockfrag.calibrate import calibrate, check_reference, load_reference, write_outputs

    config, output = _study_config(args)
    blocks = {b.name: b for b in config.blocks}
    if args.block not in blocks:
        raise PipelineError(f"--block: unknown block {args.block!r}{did_you_mean(args.block, blocks)}; blocks of "
                            f"the study: {', '.join(blocks)}")
    block = blocks[args.block]
    soil_g = args.soil_g
    if soil_g is None and args.soil:  # the names first: they cost nothing to check
        soils = {s.name: s for s in config.soils}
        if args.soil not in soils:
            raise PipelineError(f"--soil: unknown soil {args.soil!r}{did_you_mean(args.soil, soils)}; soils of the "
                                f"study: {', '.join(soils)}")
        soil_g = soils[args.soil].shear_modulus
    bed_option = _calibration_bed(args, config)
    reference = load_reference(args.reference, args.time_unit, args.angle_unit)
    print(reference.describe_units())
    record, ag = _ground_motion(args, config)
    check_reference(reference.time, reference.rotation, (len(ag) - 1) * record.dt, record.dt,
                    source=str(args.reference), time_unit=reference.time_unit)
    for option, (low, high) in (("--k-range", args.k_range), ("--xi-range", args.xi_range)):
        if not low < high:
            raise PipelineError(f"{option} {low:g} {high:g}: MIN must be below MAX")
    result = calibrate(reference.time, reference.rotation, ag, record.dt, block, model=args.model,
                       k_range=tuple(args.k_range), xi_range=tuple(args.xi_range), n_k=args.n_k, n_xi=args.n_xi,
                       soil_shear_modulus=soil_g, switch=config.switch, local=not args.grid_only,
                       log=lambda line: print(line, file=sys.stderr), confidence=args.confidence, **bed_option)
    files = write_outputs(result, reference.time, reference.rotation, ag, record.dt, block, output, config.switch,
                          **bed_option)
    if result.bed:
        print(f"bed           : {result.bed}")
    print(f"grid optimum  : k = {result.k_grid:.4g} N/m, xi = {result.xi_grid:.4f}, correlation (eq. 17) "
          f"{result.correlation_grid:.4f}")
    if not args.grid_only:
        if result.k_search is not None and (result.k_search, result.xi_search) != (result.k, result.xi):
            print(f"search optimum: k = {result.k_search:.4g} N/m, xi = {result.xi_search:.4f} (over the whole "
                  "reference)")
        window = f", window 0-{result.decisive_window:.2f} s" if result.decisive_window is not None else ""
        print(f"estimate      : k = {result.k:.4g} N/m, xi = {result.xi:.4f}, correlation (eq. 17) "
              f"{result.correlation:.4f} ({result.n_simulations} simulations, {result.seconds:.1f} s{window})")
        print("\n".join(result.interval_lines()))
    print(f"RMS error {result.rms_error:.3g} rad; peak angle {result.peak_model:.4g} rad vs reference "
          f"{result.peak_reference:.4g} rad ({result.peak_error:+.1%})")
    if result.area_over_depth is not None:
        print(f"implied A/H (eq. 19) for G_s = {soil_g:.3g} Pa and E_b = {block.E_b:.3g} Pa: "
              f"{result.area_over_depth:.4g} m")
    for path in files:
        print(f"wrote {path}")
    return 0


APPLICABILITY_OPTIONS = ("g_range", "n_g", "levels", "block_moduli", "tolerance")
"""Options of ``rockfrag applicability`` that override the study's ``[applicability]`` keys of the same name."""


def command_applicability(args) -> int:
    """``rockfrag applicability``: the rigid-base applicability sweep (applicability.nc and its figure)."""
    from rockfrag.applicability import applicability_stage
    from rockfrag.study import study_records

    overrides = {key: getattr(args, key) for key in APPLICABILITY_OPTIONS if getattr(args, key) is not None}
    config, output = _study_config(args, overrides)
    loaded = study_records(config, log=_log)
    dataset = applicability_stage(config, output, workers=args.workers, progress=not args.no_progress,
                                  loaded=loaded)
    table = (dataset.threshold_shear_modulus / 1e6).to_dataframe()["threshold_shear_modulus"].unstack()
    print(f"G_s [MPa] above which Housner is within {config.applicability.tolerance:.0%} of each model (rows: "
          "model, block, E_b [Pa]; columns: PGA / uplift PGA; NaN: not within tolerance even at the stiffest G_s):")
    print(table.round(0).to_string())
    return 0


def command_study(args) -> int:
    """``rockfrag study``: check a study file; with ``--keys``, every key with its value, range and unit."""
    from rockfrag.config import study_keys

    config, output = _study_config(args)
    if args.keys:
        rows = study_keys(config)
        width = max(len(key) for key, *_ in rows)
        print(f"{'key':<{width}}  value (this study) | default (shipped) | allowed | note (pipeline/defaults.toml)")
        for key, value, default, allowed, note in rows:
            print(f"{key:<{width}}  {value or '-'} | {default or '-'} | {allowed}" + (f" | {note}" if note else ""))
        print("NAME: a table name of your own, e.g. [blocks.cabinet]; units SI unless stated (levels of PGA/Sa in g)")
        return 0
    if args.record_set:  # the selection came from the command line, not the study file
        check_record_selection(config.record_sets, "--set", "command line")
    else:
        check_record_selection(config.record_sets, "study.record_sets", config.source)
    print(f"study '{config.name}' ({config.source}) is valid: {len(config.blocks)} blocks, {len(config.soils)} soils, "
          f"{len(config.models)} models, record sets {', '.join(config.record_sets)} (found; the records themselves "
          f"are read by rockfrag records); output {output}. rockfrag study --keys lists every key.")
    return 0


def check_record_selection(selection, field: str = "study.record_sets", source: str | None = None) -> None:
    """Check that every record set, record id, folder and file of a selection exists, without reading a record.

    Parameters
    ----------
    selection : iterable of str
        Record set names, catalogue record ids, folders or files (``study.record_sets``, ``--set``).
    field : str
        The field named in the error.
    source : str, optional
        The study file (or "command line") named in the error.

    Raises
    ------
    ConfigError
        The first name that is no set, id, folder or file ("not found", with a did-you-mean), or a catalogue
        record whose file is missing.
    """
    from rockfrag.errors import ConfigError
    from rockfrag.records import catalogue, record_sets

    sets, entries = record_sets(), {entry.id: entry for entry in catalogue()}
    for text in selection:
        text = str(text)
        if text in sets or text in entries:
            missing = [entries[i].path for i in sets.get(text, [text]) if not Path(entries[i].path).is_file()]
            if missing:
                raise ConfigError(field, f"{text!r}: catalogue file {missing[0]} not found ({len(missing)} missing)",
                                  source)
        elif not Path(text).exists():
            raise ConfigError(field, f"{text!r} not found{did_you_mean(text, [*sets, *entries])}: not a record set "
                              f"({', '.join(sorted(sets))}), a record id, a folder or a file", source)


# ---------------------------------------------------------------- the parser

def build_parser() -> argparse.ArgumentParser:
    """The ``rockfrag`` argument parser with one subcommand per stage."""
    parser = argparse.ArgumentParser(
        prog="rockfrag",
        description="Seismic fragility of unanchored rocking structures (Housner and SSI-rocking "
                    "models) from real strong-motion records. Options left out take the study's value "
                    "(the shipped pipeline/defaults.toml when no study file is given).")
    parser.add_argument("--version", action="version", version=f"rockfrag {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    study, record_set, reading, output = _study_option(), _record_set_option(), _reading_options(), _output_option()
    pool, dask = _workers_option(scheduler=False), _workers_option(scheduler=True)

    records = commands.add_parser("records", parents=[study, record_set, reading, output],
                                  help="list records with intensity measures (writes records.csv; --plot writes "
                                       "a PNG per record)")
    records.add_argument("--plot", action="store_true",
                         help="write raw-vs-processed acceleration/velocity/displacement and the 5%% "
                              "response spectrum of every record as PNG")
    records.set_defaults(handler=command_records)

    run = commands.add_parser("run", parents=[study, record_set, reading, output, dask],
                              help="run a study into the cube (cube.nc)")
    run.set_defaults(handler=command_run)
    fragility = commands.add_parser("fragility", parents=[study, record_set, reading, output, dask],
                                    help="run the whole pipeline: cube, IDA, fragility, applicability (see "
                                         "--applicability), report; ends with the answer table")
    fragility.add_argument("--applicability", action=argparse.BooleanOptionalAction, default=None,
                           help="run (or not) the soil-stiffness sweep of `rockfrag applicability` (minutes); "
                                "default: the study's [applicability] run, else only for the default study "
                                "(no study file)")
    fragility.add_argument("--skip-applicability", dest="applicability", action="store_false", default=None,
                           help=argparse.SUPPRESS)  # the old spelling of --no-applicability
    fragility.add_argument("--quiet", action="store_true",
                           help="do not print the answer table (overturning median and bounds per block and soil)")
    fragility.set_defaults(handler=command_fragility)

    calibrate = commands.add_parser("calibrate", parents=[_study_option(positional=False), reading, output],
                                    help="fit the SSI stiffness k and damping xi to a reference rotation history "
                                         "(paper eq. 17)")
    calibrate.add_argument("reference", type=Path, help="table of time and rotation (CSV or any table pandas "
                           "reads); units from --time-unit/--angle-unit or headers such as 'time [s]', 'theta [deg]'")
    calibrate.add_argument("--record", required=True, type=_name,
                           help="the ground motion: a record id (e.g. DUZCE/BOL090) or a file")
    calibrate.add_argument("--scale", type=POSITIVE, default=1.0, help="factor applied to the record (default 1)")
    calibrate.add_argument("--raw", action="store_true", help="use the record as published (no processing)")
    calibrate.add_argument("--block", default="paper", help="block name from the study (default: paper)")
    calibrate.add_argument("--soil", default=None, help="soil of the study, for the implied A/H of eq. 19")
    calibrate.add_argument("--soil-g", type=POSITIVE, default=None, metavar="PA",
                           help="soil shear modulus G_s [Pa] for the implied A/H (overrides --soil)")
    calibrate.add_argument("--k-range", type=POSITIVE, nargs=2, default=(1e8, 1e9), metavar=("MIN", "MAX"),
                           help="stiffness search range [N/m] (default 1e8 1e9: the paper's 1e5-9e5 kN/m and up to "
                                "the coverage benchmark's 1e9)")
    calibrate.add_argument("--xi-range", type=_number_type(0, high=1, high_open=True), nargs=2,
                           default=(0.01, 0.07), metavar=("MIN", "MAX"),
                           help="damping-ratio grid [-] (default 0.01 0.07)")
    calibrate.add_argument("--n-k", type=GRID_SIZE, default=25, help="coarse grid points in k (log-spaced, >= 2)")
    calibrate.add_argument("--n-xi", type=GRID_SIZE, default=7, help="coarse grid points in xi (>= 2)")
    calibrate.add_argument("--grid-only", action="store_true", help="the coarse grid only (the paper's procedure)")
    calibrate.add_argument("--confidence", type=_number_type(0, high=1, low_open=True, high_open=True), default=0.9,
                           help="two-sided level of the profile-likelihood intervals of k and xi (default 0.9)")
    calibrate.add_argument("--time-unit", default=None, help="time unit of the reference: s, ms, us, min (default: "
                           "from its header, else s)")
    calibrate.add_argument("--angle-unit", default=None, help="angle unit of the reference: rad, mrad, deg "
                           "(default: from its header, else rad)")
    calibrate.add_argument("--model", default="ssi", help="the model to calibrate: any with a foundation, e.g. "
                           "ssi, ssi-paper, winkler (default ssi)")
    calibrate.add_argument("--bed", default=None, metavar="BED",
                           help="winkler's bed: continuous or two-spring (default: the study's [solver] bed)")
    calibrate.set_defaults(handler=command_calibrate)

    applicability = commands.add_parser(
        "applicability", parents=[study, record_set, reading, output, pool],
        help="sweep the soil shear modulus and compare Housner with SSI-rocking (writes applicability.nc and a "
             "figure; the same sweep as the fragility stage, from the study's [applicability] table)")
    applicability.add_argument("--g-range", type=POSITIVE, nargs=2, default=None, metavar=("MIN", "MAX"),
                               help="soil shear modulus range [Pa] (study default 1e7 1e11)")
    applicability.add_argument("--n-g", type=GRID_SIZE, default=None, help="moduli in the sweep (log-spaced; "
                               "study default 13)")
    applicability.add_argument("--levels", type=POSITIVE, nargs="+", default=None,
                               help="PGA levels as multiples of each block's uplift PGA g tan(alpha) "
                                    "(study default 1.5 2.5 4)")
    applicability.add_argument("--block-moduli", type=POSITIVE, nargs="+", default=None, metavar="PA",
                               help="block Young's moduli E_b to compare [Pa] (study default 3e10 2.1e11)")
    applicability.add_argument("--tolerance", type=POSITIVE, default=None,
                               help="allowed |SSI/Housner - 1| (study default 0.1)")
    applicability.set_defaults(handler=command_applicability)

    study_command = commands.add_parser("study", parents=[study, record_set, reading, output],
                                        help="check a study file (nothing is run or written); --keys lists every "
                                             "study key with its value, allowed range and unit")
    study_command.add_argument("--keys", action="store_true",
                               help="print every study key: its value in this study, what it must be (type, range, "
                                    "unit) and the shipped defaults' note")
    study_command.set_defaults(handler=command_study, writes_output=False)
    return parser


EXIT_INTERNAL_ERROR = 3

EXIT_CODES = """exit status:
  0    success
  1    finished, but some records were skipped (each named on stderr with its reason)
  2    user error: bad input file, option or study value, output folder unusable or in use
       (one line naming the file, field and allowed range; nothing already written is lost)
  3    internal error (a bug): one line naming the stage and input, the traceback in a log file
  130  interrupted (Ctrl-C); files already written are complete"""


def _input_of(args) -> str:
    """The input a command was processing, for the one-line internal-error message."""
    parts = []
    for name, label in (("study", "study"), ("reference", "reference"), ("record", "record"),
                        ("record_set", "records"), ("processing", "recipe")):
        value = getattr(args, name, None)
        if value:
            parts.append(f"{label} {', '.join(map(str, value)) if isinstance(value, list) else value}")
    return "; ".join(parts) or "the shipped defaults"


def _error_log_path(args) -> Path:
    """A new log file in the output folder, or in the temporary folder if that is not writable."""
    name = f"rockfrag-error-{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}.log"
    output = getattr(args, "locked_output", None) or getattr(args, "output", None) or Path("reports")
    for folder in (output, Path(tempfile.gettempdir())):
        try:
            Path(folder).mkdir(parents=True, exist_ok=True)
            path = Path(folder) / name
            with open(path, "x", encoding="utf-8"):
                pass
            return path
        except OSError:
            continue
    return Path(tempfile.gettempdir()) / name


def _report_internal_error(args, error) -> int:
    """Last line of defence: one line on stderr, the full traceback in a log file; rc 3."""
    stage = getattr(args, "command", "?")
    notes = "; ".join(getattr(error, "__notes__", []))
    text = "".join(traceback.format_exception(error))
    log_path = _error_log_path(args)
    try:
        log_path.write_text(f"rockfrag {__version__} {stage}: {' '.join(sys.argv)}\n{text}", encoding="utf-8")
        where = f"traceback in {log_path}"
    except OSError:
        where = "traceback could not be written to a log file"
    message = " ".join(f"{type(error).__name__}: {error}".split())[:300]
    print(f"rockfrag: internal error in stage '{stage}' while processing {_input_of(args)}"
          f"{' (' + notes + ')' if notes else ''}: {message}; {where}; please report it", file=sys.stderr)
    return EXIT_INTERNAL_ERROR


def _file_problem(error: OSError) -> str | None:
    """One line for an OS error about a named file (disk full, permission, missing folder)."""
    if error.filename is None or not error.strerror:
        return None
    return f"{error.filename}: {error.strerror}"


def _output_folder(args) -> Path | None:
    """The folder the command writes to: --output, else the study's study.output (None: it writes nothing)."""
    if not getattr(args, "writes_output", True):
        return None
    if getattr(args, "output", None) is not None:
        return Path(args.output)
    if not hasattr(args, "study"):
        return None
    return _study_config(args)[1]


def _parse_arguments(parser, argv):
    """The parsed namespace; a usage error is one line (argparse's own, without the usage block)."""
    captured = io.StringIO()
    try:
        with contextlib.redirect_stderr(captured):
            return parser.parse_args(argv)
    except SystemExit as stop:
        lines = [line for line in captured.getvalue().splitlines() if line.strip()]
        if stop.code in (0, None) or not lines:
            sys.stderr.write(captured.getvalue())
            raise
        command = lines[-1].split(": error:", 1)[0]
        print(f"{lines[-1]} (see '{command} --help')", file=sys.stderr)
        raise SystemExit(EXIT_USER_ERROR) from None


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Print a warning as one ``rockfrag: warning:`` line (no source location: users read it, not developers)."""
    print(f"rockfrag: warning: {' '.join(str(message).splitlines())}", file=sys.stderr)


@functools.cache
def _command_parser() -> argparse.ArgumentParser:
    """``build_parser()`` with the exit codes under its help, built once per process.

    Parsing leaves the parser unchanged, so it is reused: the tests run ``main`` over a thousand times in one
    process, and a build takes about 4 ms.
    """
    parser = build_parser()
    parser.epilog = EXIT_CODES
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    return parser


def main(argv=None) -> int:
    """Run the ``rockfrag`` command line; returns the exit code (see ``EXIT_CODES``)."""
    warnings.showwarning = _one_line_warning
    args = _parse_arguments(_command_parser(), argv)
    try:
        output = _output_folder(args)
        if output is None:
            return args.handler(args)
        args.locked_output = output
        with output_lock(output, wait=getattr(args, "wait", False), notify=lambda line: _log(f"rockfrag: {line}")):
            return args.handler(args)
    except PipelineError as error:
        print(f"rockfrag: error: {' '.join(str(error).splitlines())}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("rockfrag: interrupted; files already written are complete", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of our output went away (`rockfrag study --keys | head`): not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as error:
        problem = _file_problem(error)
        if problem is None:
            return _report_internal_error(args, error)
        print(f"rockfrag: error: {problem}", file=sys.stderr)
        return EXIT_USER_ERROR
    except Exception as error:  # noqa: BLE001 - the last line of defence, see EXIT_CODES
        return _report_internal_error(args, error)


if __name__ == "__main__":
    sys.exit(main())
