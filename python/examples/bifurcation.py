# %% [markdown]
# # A bifurcation analysis
#
# Follow the periodic orbit of the default case in Ω by continuation, with its Floquet
# multipliers, power and bifurcations; compare with a brute-force sweep.

# %%
import numpy as np

import vibrotribo as vt

cfg = vt.Config()
branch = vt.continue_(cfg, "omega_ratio", 0.70, 0.74, max_points=200)
print(branch)
points = branch.to_pandas()
print(points[["branch", "parameter", "stable", "spectral_radius", "average_power_w"]].head())
for b in branch.bifurcations:
    print(b["kind"], f"at Ω = {b['parameter']:.5f}")

# %% [markdown]
# The brute-force view: a sweep with each point's Floquet multiplier.

# %%
sweep = vt.sweep(cfg, "omega_ratio", vt.grid(0.70, 0.74, 5), transient=100, recorded=20, floquet=True,
                 mechanics_only=True)
print(sweep.summary.to_pandas()[["param", "period", "max_abs_multiplier"]])
radius = np.asarray(sweep.summary["max_abs_multiplier"])
print("stable points:", int(np.sum(radius < 1)))
