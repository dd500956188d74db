"""
Your own records
================

rockfrag reads strong-motion records in the formats agencies and databases publish: PEER NGA ``.AT2``, plain
text and CSV, K-NET/KiK-net, CSMIP Volume 1, ASDF (gmprocess workspaces) and every waveform format obspy reads
(MiniSEED, SAC, ...). Every reader gives ground acceleration in m/s^2; the units come from the file where it
states them, else from you. This tutorial reads one file of each kind, processes one, and uses a folder of your
own files in a study.
"""

# %%
# Text and CSV
# ------------
# The most common exchange format. Two columns (time [s], acceleration) or one column (acceleration, with the
# time step given); a unit in the header (``acc [g]``, ``acceleration (cm/s^2)``) is read, header lines and
# ``#`` comments are skipped. Here we write one from a shipped record, as a colleague might send it.
import tempfile
from pathlib import Path

import numpy as np

import rockfrag

[bolu], failures = rockfrag.load_records("DUZCE/BOL090")  # a catalogue record: (records, failures)
folder = Path(tempfile.mkdtemp(prefix="my-records-"))
time = np.arange(bolu.trace.stats.npts) * bolu.dt
in_g = bolu.acceleration / 9.80665
np.savetxt(folder / "bolu-two-columns.csv", np.column_stack([time, in_g]), delimiter=",", fmt="%.6g",
           header="time [s], acc [g]", comments="")
np.savetxt(folder / "bolu-one-column.txt", in_g, fmt="%.6g")  # in g, without a header

# %%
# ``load_records`` reads a file of one's own as it reads a record set: it returns the records it read and,
# for each file it could not read, the reason. A two-column file states its units and time step; a one-column
# file needs them from you.
[two_columns], _ = rockfrag.load_records(folder / "bolu-two-columns.csv")  # units and dt from the file
[one_column], _ = rockfrag.load_records(folder / "bolu-one-column.txt", units="g", dt=0.01)
for record in (two_columns, one_column):
    print(f"{record.id}: {record.acceleration.size} samples at dt = {record.dt:.4g} s, "
          f"PGA {np.abs(record.acceleration).max() / 9.80665:.4f} g")

# %%
# A one-column file without ``units`` or ``dt`` is not read, with a reason that says what to give, never a
# guess:
records, failures = rockfrag.load_records(folder / "bolu-one-column.txt")
print(records, failures[0], sep="\n")

# %%
# K-NET and KiK-net
# -----------------
# obspy reads the NIED formats; the header's scale factor gives gal, converted to m/s^2. obspy ships a short
# K-NET file in its tests:
import obspy

knet_file = Path(obspy.__file__).parent / "io" / "nied" / "tests" / "data" / "test.knet"
[knet], _ = rockfrag.load_records(knet_file)
print(knet.id, knet.trace.stats.starttime, f"{knet.acceleration.size} samples, {1 / knet.dt:g} Hz")
print(f"PGA {np.abs(knet.acceleration).max():.4f} m/s^2")

# %%
# CSMIP Volume 1 and ASDF
# -----------------------
# A CSMIP Volume 1 file holds the three channels of a station; an ASDF file (HDF5) holds the raw counts of
# whole networks with their instrument responses, which rockfrag removes. Each component becomes a record of
# its own, the vertical marked as such. Both kinds are in the shipped catalogue (USGS demo data of gmprocess,
# public domain); a record's ``metadata["file"]`` is the file it was read from, which we copy here as if it
# were one of ours (in a folder of its own: the last section uses the first folder in a study).
import shutil

station_files = Path(tempfile.mkdtemp(prefix="my-stations-"))

for catalogue_id, name in (("RIDGECREST/CI.CLC.HNE", "CICLC.v1"), ("SOUTHNAPA/CE.68150.HNE", "workspace.h5")):
    [shipped], _ = rockfrag.load_records(catalogue_id)
    shutil.copy(shipped.metadata["file"], station_files / name)
    components, _ = rockfrag.load_records(station_files / name)
    for record in components:
        print(f"{name}: {record.id} component {record.component}{' (vertical)' if record.is_vertical else ''}, "
              f"PGA {np.abs(record.acceleration).max() / 9.80665:.3f} g")

# %%
# Processing
# ----------
# Before any run each record is processed by the shipped recipe (``pipeline/processing.toml``: demean,
# detrend, taper, zero-padded 4th-order Butterworth band-pass, baseline correction), each step written into
# the trace's provenance. A recipe of your own is a TOML file of the same layout (``[study] processing``;
# ``rockfrag.load_recipe`` reads one). ``intensity_measures`` gives the measures of the processed record, the
# columns of ``records.csv``, in SI units.
import matplotlib.pyplot as plt

record = two_columns
processed = rockfrag.process_record(record)
print("\n".join(processed.trace.stats.processing))
measures = rockfrag.intensity_measures(processed)
print({name: round(value, 4) for name, value in measures.items()})

fig, axes = plt.subplots(2, 1, figsize=(7, 4.5), sharex=True)
axes[0].plot(record.trace.times(), record.acceleration / 9.80665, lw=0.6, label="as read")
axes[0].plot(processed.trace.times(), processed.acceleration / 9.80665, lw=0.6, label="processed")
axes[0].set_ylabel("acceleration [g]")
axes[0].legend(loc="upper right")
velocity = np.cumsum(processed.acceleration) * processed.dt
raw_velocity = np.cumsum(record.acceleration - record.acceleration.mean()) * record.dt
axes[1].plot(record.trace.times(), raw_velocity, lw=0.6, label="as read (demeaned)")
axes[1].plot(processed.trace.times(), velocity, lw=0.6, label="processed")
axes[1].set_xlabel("time [s]")
axes[1].set_ylabel("velocity [m/s]")
axes[1].legend(loc="upper right")
fig.tight_layout()

# %%
# Your records in a study
# -----------------------
# A folder (or files) in ``[study] record_sets`` beside record ids and set names; ``[study] units`` and
# ``dt`` serve the files that do not state them (a file whose header states other units is refused, not
# converted twice). A file with the same samples as a record read before it is skipped, with the reason: here
# the two copies of Bolu 090 we wrote, which are the catalogue's Bolu 090.
records, failures = rockfrag.load_records(["DUZCE/BOL090", str(folder), "KOBE/NIS000"], units="g", dt=0.01)
print([record.id for record in records])
for failure in failures:
    print("skipped:", failure)

# %%
# On the command line the same folder goes to ``--set`` (``rockfrag records --set my-records/ --units g
# --dt 0.01`` writes the table of measures, ``--plot`` a figure per record).
