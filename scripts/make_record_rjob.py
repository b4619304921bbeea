#!/usr/bin/env python3
"""Writes configs/records/rjob_vertical_acceleration.csv from ObsPy's bundled example
seismogram (not run by the tests; needs ObsPy: `python3 -m venv /tmp/v && /tmp/v/bin/pip
install obspy && /tmp/v/bin/python scripts/make_record_rjob.py`).

What it does (see configs/records/README.md):
1. `obspy.read()` without arguments returns ObsPy's example stream: three 30 s channels of
   station BW.RJOB (2009-08-24 00:20:03 UTC, 100 samples/s, 3000 samples each), in counts of
   a velocity seismometer. The vertical component is channel EHZ.
2. Counts -> ground velocity: divide by the instrument's nominal sensitivity
   2516778400 counts/(m/s) (the example's documented PAZ; no deconvolution of the response,
   i.e. the response is taken as flat in its passband), then subtract the mean.
3. Velocity -> acceleration: second-order central differences (numpy.gradient with the
   sample interval 0.01 s; one-sided at the two ends).
4. Scale so that the largest |acceleration| is exactly PEAK m/s^2 (the absolute calibration
   does not matter: configurations state the peak they use).
5. Write time_s (from 0) and acceleration_m_s2, 10 significant digits.
"""
import pathlib

import numpy as np
import obspy

PEAK = 1.0  # m/s^2, largest |acceleration| of the written record
SENSITIVITY = 2516778400.0  # counts per m/s, from the example's PAZ (obspy.core.stream)

trace = obspy.read().select(channel="EHZ")[0]
dt = trace.stats.delta
velocity = trace.data.astype(np.float64) / SENSITIVITY
velocity -= velocity.mean()
acceleration = np.gradient(velocity, dt)
nominal_peak = np.abs(acceleration).max()
acceleration *= PEAK / nominal_peak
time = np.arange(trace.stats.npts) * dt

out = pathlib.Path(__file__).resolve().parent.parent / "configs" / "records" / "rjob_vertical_acceleration.csv"
with open(out, "w") as f:
    f.write("time_s,acceleration_m_s2\n")
    for t, a in zip(time, acceleration):
        f.write(f"{t:.2f},{a:.10g}\n")
print(f"{trace.id} {trace.stats.starttime} {trace.stats.npts} samples at {trace.stats.sampling_rate} Hz")
print(f"nominal peak acceleration {nominal_peak:.6g} m/s^2, scaled by {PEAK / nominal_peak:.6g} to {PEAK} m/s^2")
print(f"obspy {obspy.__version__}; wrote {out}")
