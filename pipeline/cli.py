"""pipeline.cli - the ``rockfrag`` command; subcommands are named after pipeline stages.

Input : command-line arguments. Output: files in the output folder (``reports/`` by default) and a
short summary on stdout. A user error (bad record, bad parameter) prints one line on stderr and
exits with status 2, without a traceback; files already written stay valid.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pipeline import __version__
from pipeline.errors import PipelineError

EXIT_USER_ERROR = 2
EXIT_PARTIAL = 1


def _add_record_arguments(parser):
    parser.add_argument("--set", dest="record_set", action="append", metavar="NAME",
                        help="record set from records/MANIFEST.csv (far-field, near-field-pulse, "
                             "near-field-no-pulse, near-field, peer-original, bolu, all), a record id, "
                             "or a folder/file of your own records; repeatable (default: all)")
    parser.add_argument("--units", default=None,
                        help="acceleration units of your own files when the format does not state "
                             "them (g, m/s^2, cm/s^2, gal)")
    parser.add_argument("--processing", type=Path, default=None, metavar="TOML",
                        help="processing recipe (default: pipeline/processing.toml)")
    parser.add_argument("--output", type=Path, default=Path("reports"), metavar="DIR",
                        help="output folder (default: reports)")
    parser.add_argument("--no-progress", action="store_true", help="hide progress bars")


def _load(args):
    from pipeline.processing import load_recipe
    from pipeline.records import load_records

    recipe = load_recipe(args.processing)
    records, failures = load_records(args.record_set or ["all"], units=args.units)
    for failure in failures:
        print(f"rockfrag: skipped {failure}", file=sys.stderr)
    return records, failures, recipe


def command_records(args) -> int:
    from pipeline.records_report import TABLE_COLUMNS, records_stage

    records, failures, recipe = _load(args)
    if not records:
        raise PipelineError("no record could be read; nothing to do")
    table, pngs = records_stage(records, recipe, args.output, plot=args.plot,
                                progress=not args.no_progress)
    import pandas as pd

    shown = table[["id", "event", "station", "component", *TABLE_COLUMNS]].rename(columns=TABLE_COLUMNS)
    with pd.option_context("display.max_rows", None, "display.width", 200, "display.max_colwidth", 28):
        print(shown.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"\nwrote {args.output / 'records.csv'} ({len(table)} records)")
    if pngs:
        print(f"wrote {len(pngs)} figures in {args.output / 'records'}/")
    flagged = table[table["qa_flags"].astype(bool)]
    if len(flagged):
        print(f"QA: {len(flagged)} record(s) flagged (kept): {', '.join(flagged['id'])}; see qa_flags")
    return EXIT_PARTIAL if failures else 0


def _study_config(args):
    from pipeline.config import load_study

    overrides = {}
    if getattr(args, "record_set", None):
        overrides.setdefault("study", {})["record_sets"] = args.record_set
    config = load_study(args.study, overrides or None)
    return config, Path(args.output) if args.output else config.output


def command_run(args) -> int:
    from pipeline.study import run_study

    config, output = _study_config(args)
    dataset, stats = run_study(config, output=output, workers=1 if args.serial else None,
                               scheduler=args.scheduler, dask_workers=args.workers,
                               progress=not args.no_progress)
    runs = stats["runs_computed"]
    rate = f", {runs / stats['seconds']:.0f} runs/s" if runs else ""
    print(f"wrote {output / 'cube.nc'} ({stats['seconds']:.1f} s{rate}; "
          f"{stats['cells_reused']} of {stats['cells']} cells reused from checkpoints)")
    return EXIT_PARTIAL if stats["failures"] else 0


def command_fragility(args) -> int:
    """The whole pipeline: study cube, IDA, fragility and risk, report."""
    import time

    from pipeline.fragility import fragility_stage
    from pipeline.ida import ida_stage
    from pipeline.report import report_stage
    from pipeline.study import run_study

    from pipeline.study import study_records

    started = time.perf_counter()
    config, output = _study_config(args)
    loaded = study_records(config, log=lambda message: print(message, file=sys.stderr))
    cube, stats = run_study(config, output=output, workers=1 if args.serial else None,
                            scheduler=args.scheduler, dask_workers=args.workers, progress=not args.no_progress,
                            loaded=loaded)
    print(f"wrote {output / 'cube.nc'} ({stats['cells_reused']} of {stats['cells']} cells from checkpoints)")
    ida = ida_stage(cube, output)
    print(f"wrote {output / 'ida.nc'}")
    if "capacity_scale_factor" in cube:  # measure ranking from the adaptive capacities (no solver runs)
        from pipeline.efficiency import efficiency_stage

        efficiency_stage(cube, loaded[0], config, output)
        print(f"wrote {output / 'efficiency.nc'} and {output / 'efficiency.csv'}")
    fragility, risk = fragility_stage(cube, ida, config, output)
    for name in ("fragility.nc", "fragility.csv", "fragility_pelicun.csv"):
        print(f"wrote {output / name}")
    applicability = None
    if not args.skip_applicability:
        from pipeline.applicability import applicability_stage

        applicability = applicability_stage(config, output, workers=1 if args.serial else None,
                                            progress=not args.no_progress, loaded=loaded)
    pdf, pngs = report_stage(config, cube, ida, fragility, risk, output, time.perf_counter() - started,
                             applicability, loaded)
    print(f"wrote {pdf} ({len(pngs)} pages) and {len(pngs)} figures in {output / 'figures'}/")
    print(f"done in {time.perf_counter() - started:.0f} s")
    return EXIT_PARTIAL if stats["failures"] else 0


def _block_from_study(name, study):
    from pipeline.config import load_study

    config = load_study(study)
    blocks = {b.name: b for b in config.blocks}
    if name not in blocks:
        raise PipelineError(f"unknown block {name!r}; blocks of the study: {', '.join(blocks)}")
    return blocks[name], config


def _ground_motion(args):
    from pipeline.processing import load_recipe, process_record
    from pipeline.records import load_records

    records, failures = load_records(args.record, units=args.units)
    if failures:
        raise failures[0]
    if len(records) != 1:
        raise PipelineError(f"--record {args.record!r} selects {len(records)} records; name exactly one")
    record = records[0] if args.raw else process_record(records[0], load_recipe(args.processing))
    if not args.scale > 0:
        raise PipelineError(f"--scale {args.scale}: must be > 0")
    return record, record.acceleration * args.scale


def command_calibrate(args) -> int:
    from pipeline.calibrate import calibrate, load_reference, write_outputs

    block, config = _block_from_study(args.block, args.study)
    ref_time, ref_rotation = load_reference(args.reference, args.time_unit, args.angle_unit)
    record, ag = _ground_motion(args)
    soil_g = args.soil_g
    if soil_g is None and args.soil:
        soils = {s.name: s for s in config.soils}
        if args.soil not in soils:
            raise PipelineError(f"unknown soil {args.soil!r}; soils of the study: {', '.join(soils)}")
        soil_g = soils[args.soil].shear_modulus
    result = calibrate(ref_time, ref_rotation, ag, record.dt, block, k_range=tuple(args.k_range),
                       xi_range=tuple(args.xi_range), n_k=args.n_k, n_xi=args.n_xi, soil_shear_modulus=soil_g,
                       switch=config.switch, local=not args.grid_only)
    files = write_outputs(result, ref_time, ref_rotation, ag, record.dt, block, args.output, config.switch)
    print(f"grid optimum : k = {result.k_grid:.4g} N/m, xi = {result.xi_grid:.4f}, correlation {result.correlation_grid:.4f}")
    print(f"local optimum: k = {result.k:.4g} N/m, xi = {result.xi:.4f}, correlation {result.correlation:.4f}")
    print(f"RMS error {result.rms_error:.3g} rad; peak angle {result.peak_model:.4g} rad vs reference "
          f"{result.peak_reference:.4g} rad ({result.peak_error:+.1%})")
    if result.area_over_depth is not None:
        print(f"implied A/H (eq. 19) for G_s = {soil_g:.3g} Pa and E_b = {block.E_b:.3g} Pa: "
              f"{result.area_over_depth:.4g} m")
    for path in files:
        print(f"wrote {path}")
    return 0


def command_applicability(args) -> int:
    import numpy as np

    from pipeline.applicability import run_applicability, write_applicability
    from pipeline.study import study_records

    config, output = _study_config(args)
    if args.g_range[0] <= 0 or args.g_range[1] <= args.g_range[0]:
        raise PipelineError(f"--g-range {args.g_range}: need 0 < G_min < G_max [Pa]")
    records, _, _ = study_records(config, log=lambda message: print(message, file=sys.stderr))
    dataset = run_applicability(records, config.blocks, shear_moduli=np.geomspace(*args.g_range, args.n_g),
                                block_moduli=tuple(args.block_moduli), level_factors=tuple(args.levels),
                                tolerance=args.tolerance, workers=1 if args.serial else None,
                                progress=not args.no_progress)
    paths = write_applicability(dataset, output)
    table = (dataset.threshold_shear_modulus / 1e6).to_dataframe()["threshold_shear_modulus"].unstack()
    print(f"G_s [MPa] above which Housner is within {args.tolerance:.0%} of SSI (rows: block, E_b [Pa]; "
          "columns: PGA / uplift PGA; NaN: not within tolerance even at the stiffest G_s):")
    print(table.round(0).to_string())
    for path in paths:
        print(f"wrote {path}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rockfrag",
        description="Seismic fragility of unanchored rocking structures (Housner and SSI-rocking "
                    "models) from real strong-motion records.")
    parser.add_argument("--version", action="version", version=f"rockfrag {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    records = commands.add_parser("records", help="list records with intensity measures "
                                  "(writes records.csv; --plot writes a PNG per record)")
    _add_record_arguments(records)
    records.add_argument("--plot", action="store_true",
                         help="write raw-vs-processed acceleration/velocity/displacement and the 5%% "
                              "response spectrum of every record as PNG")
    records.set_defaults(handler=command_records)

    for name, handler, text in (("run", command_run, "run a study into the cube (cube.nc)"),
                                ("fragility", command_fragility,
                                 "run the whole pipeline: cube, IDA, fragility, report")):
        sub = commands.add_parser(name, help=text)
        sub.add_argument("study", nargs="?", type=Path, default=None,
                         help="study TOML file (default: the shipped pipeline/defaults.toml)")
        sub.add_argument("--set", dest="record_set", action="append", metavar="NAME",
                         help="record set(s), overriding the study's study.record_sets")
        sub.add_argument("--output", type=Path, default=None, metavar="DIR",
                         help="output folder (default: the study's study.output, reports/)")
        sub.add_argument("--scheduler", metavar="ADDRESS", default=None,
                         help="run on an existing dask.distributed cluster, e.g. tcp://host:8786")
        sub.add_argument("--workers", type=int, default=None, metavar="N",
                         help="start a local dask cluster with N worker processes")
        sub.add_argument("--serial", action="store_true", help="run in this process (debugging)")
        sub.add_argument("--no-progress", action="store_true", help="hide progress bars")
        if name == "fragility":
            sub.add_argument("--skip-applicability", action="store_true",
                             help="skip the soil-stiffness sweep of `rockfrag applicability` (saves minutes)")
        sub.set_defaults(handler=handler)
    calibrate = commands.add_parser("calibrate", help="fit the SSI stiffness k and damping xi to a reference "
                                    "rotation history (paper eq. 17)")
    calibrate.add_argument("reference", type=Path, help="table of time and rotation (CSV or any table pandas "
                           "reads); units from --time-unit/--angle-unit or headers such as 'time [s]', 'theta [deg]'")
    calibrate.add_argument("--record", required=True, help="the ground motion: a record id (e.g. DUZCE/BOL090) "
                           "or a file")
    calibrate.add_argument("--scale", type=float, default=1.0, help="factor applied to the record (default 1)")
    calibrate.add_argument("--raw", action="store_true", help="use the record as published (no processing)")
    calibrate.add_argument("--processing", type=Path, default=None, metavar="TOML", help="processing recipe")
    calibrate.add_argument("--units", default=None, help="acceleration units of a record file that does not state them")
    calibrate.add_argument("--block", default="paper", help="block name from the study (default: paper)")
    calibrate.add_argument("--study", type=Path, default=None, help="study TOML holding the block (default: shipped)")
    calibrate.add_argument("--soil", default=None, help="soil of the study, for the implied A/H of eq. 19")
    calibrate.add_argument("--soil-g", type=float, default=None, metavar="PA", help="soil shear modulus G_s [Pa] "
                           "for the implied A/H (overrides --soil)")
    calibrate.add_argument("--k-range", type=float, nargs=2, default=[1e8, 9e8], metavar=("MIN", "MAX"),
                           help="stiffness grid [N/m] (default 1e8 9e8 = the paper's 1e5-9e5 kN/m)")
    calibrate.add_argument("--xi-range", type=float, nargs=2, default=[0.01, 0.07], metavar=("MIN", "MAX"),
                           help="damping-ratio grid [-] (default 0.01 0.07)")
    calibrate.add_argument("--n-k", type=int, default=25, help="grid points in k (log-spaced)")
    calibrate.add_argument("--n-xi", type=int, default=7, help="grid points in xi")
    calibrate.add_argument("--grid-only", action="store_true", help="skip the local optimisation")
    calibrate.add_argument("--time-unit", choices=["s", "ms"], default=None)
    calibrate.add_argument("--angle-unit", choices=["rad", "mrad", "deg"], default=None)
    calibrate.add_argument("--output", type=Path, default=Path("reports"), metavar="DIR")
    calibrate.set_defaults(handler=command_calibrate)

    applicability = commands.add_parser("applicability", help="sweep the soil shear modulus and compare "
                                        "Housner with SSI-rocking (writes applicability.nc and a figure)")
    applicability.add_argument("study", nargs="?", type=Path, default=None, help="study TOML (blocks, records)")
    applicability.add_argument("--set", dest="record_set", action="append", metavar="NAME",
                               help="record set(s), overriding the study's")
    applicability.add_argument("--g-range", type=float, nargs=2, default=[10e6, 100e9], metavar=("MIN", "MAX"),
                               help="soil shear modulus range [Pa] (default 1e7 1e11)")
    applicability.add_argument("--n-g", type=int, default=13, help="moduli in the sweep (log-spaced)")
    applicability.add_argument("--levels", type=float, nargs="+", default=[1.5, 2.5, 4.0],
                               help="PGA levels as multiples of each block's uplift PGA g tan(alpha)")
    applicability.add_argument("--block-moduli", type=float, nargs="+", default=[30e9, 210e9], metavar="PA",
                               help="block Young's moduli E_b to compare [Pa] (default concrete and steel)")
    applicability.add_argument("--tolerance", type=float, default=0.10, help="allowed |SSI/Housner - 1|")
    applicability.add_argument("--output", type=Path, default=None, metavar="DIR")
    applicability.add_argument("--serial", action="store_true", help="run in this process")
    applicability.add_argument("--no-progress", action="store_true")
    applicability.set_defaults(handler=command_applicability)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except PipelineError as error:
        print(f"rockfrag: error: {error}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("rockfrag: interrupted; files already written are complete", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
