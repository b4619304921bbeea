# %% [markdown]
# # Designing a harvester
#
# Choose a load, check the power against it, and see what the harvester delivers on a
# periodic orbit; then drive it by a measured base motion given as arrays.

# %%
import numpy as np

import vibrotribo as vt

cfg = vt.Config(run__periods=40, run__transient_periods=20)

# %% [markdown]
# Power against the load resistance on one mechanical run, and the optimum.

# %%
loads = vt.load_sweep(cfg, steps=13, vq_points=None)
print(f"optimal load {loads.optimum['resistance_ohm']:.3e} Ω: {loads.optimum['average_power_w']:.4e} W")
design = cfg.with_(harvester__load_resistance=float(loads.optimum["resistance_ohm"]))

# %% [markdown]
# The periodic orbit at the chosen load, its stability and the power on it.

# %%
orbit = vt.periodic(design)
print(f"period {orbit.period}, stable {orbit.stable}, |μ|max {orbit.spectral_radius:.4f}")
print(f"power on the orbit {orbit.average_power_w} W")

# %% [markdown]
# The same harvester driven by a recorded base acceleration (here a decaying 5 Hz burst made
# with numpy), without writing a file by hand.

# %%
t = np.linspace(0.0, 8.0, 8001)
a = 30.0 * np.sin(2 * np.pi * 5.0 * t) * np.exp(-0.2 * t)
shaken = vt.with_base_motion(design, t, a, "acceleration", omega_ratio=0.7)
run = vt.simulate(shaken, samples=False)
print(f"{run.summary['impacts']} impacts, average power {run.average_power_w} W")
