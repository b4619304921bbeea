# %% [markdown]
# # The paper's study in brief
#
# The default configuration is the paper's three-mass harvester. This notebook runs it once,
# sweeps the excitation frequency across the impacting regime, and finds the optimal mass
# ratio on a coarse grid, each a few seconds. SI units throughout.

# %%
import numpy as np

import vibrotribo as vt

cfg = vt.Config()
print(cfg["oscillator.masses"], cfg["oscillator.gaps"], cfg["excitation.omega_ratio"])

# %% [markdown]
# One run: the average power after the transient and the exact energy of every period.

# %%
run = vt.simulate(cfg.with_(run__periods=60, run__transient_periods=30))
print(run)
energies = run.period_energy_j
assert energies is not None
print(f"average power {run.average_power_w:.4e} W over {len(energies) - 30} periods")

# %% [markdown]
# A frequency sweep: the period of the motion and the power at each Ω.

# %%
sweep = vt.sweep(cfg, "omega_ratio", vt.grid(0.55, 0.95, 9), transient=80, recorded=30)
table = sweep.summary
best = int(np.nanargmax(table["average_power_w"]))
print(f"best Ω = {table['param'][best]:.3f}: {table['average_power_w'][best]:.4e} W, period {table['period'][best]}")

# %% [markdown]
# The optimal mass ratio R_mo(Ω) on a coarse grid, beside the paper's quadratic fit.

# %%
opt = vt.optimize_mass_ratio(cfg, omega_steps=3, rm_from=1.5, rm_to=5.0, rm_steps=8, transient=60, recorded=20)
print(opt.optimum.to_pandas())
