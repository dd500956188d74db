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
    shown = table[["id", "event", "station", "component", *TABLE_COLUMNS]].rename(columns=TABLE_COLUMNS)
    with_options = __import__("pandas").option_context("display.max_rows", None, "display.width", 200,
                                                       "display.max_colwidth", 28)
    with with_options:
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

    started = time.perf_counter()
    config, output = _study_config(args)
    cube, stats = run_study(config, output=output, workers=1 if args.serial else None,
                            scheduler=args.scheduler, dask_workers=args.workers, progress=not args.no_progress)
    print(f"wrote {output / 'cube.nc'} ({stats['cells_reused']} of {stats['cells']} cells from checkpoints)")
    ida = ida_stage(cube, output)
    print(f"wrote {output / 'ida.nc'}")
    fragility, risk = fragility_stage(cube, ida, config, output)
    for name in ("fragility.nc", "fragility.csv", "fragility_pelicun.csv"):
        print(f"wrote {output / name}")
    pdf, pngs = report_stage(config, cube, ida, fragility, risk, output, time.perf_counter() - started)
    print(f"wrote {pdf} ({len(pngs)} pages) and {len(pngs)} figures in {output / 'figures'}/")
    print(f"done in {time.perf_counter() - started:.0f} s")
    return EXIT_PARTIAL if stats["failures"] else 0


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
        sub.set_defaults(handler=handler)
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
