"""Redraws the paper's Fig. 22 from Python: time histories in the chatter case
(m1 = m3 = 50 g, R_m = 3, δ1 = δ2 = 5 mm) at Ω = 0.600 (chatter) and Ω = 0.765 (near
resonance): the gaps D1 and D2 and the current I through the 100 kΩ load over the last two
excitation periods of a 200-period run.

    pip install ./python matplotlib       # from the repository's root
    python examples/python/quickstart.py  # writes fig22_quickstart.png (or give a path)
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import vibrotribo as vt  # noqa: E402

CHATTER = Path(__file__).resolve().parents[2] / "configs" / "chatter.toml"


def main(out: str = "fig22_quickstart.png", periods: int = 200) -> None:
    fig, axes = plt.subplots(3, 2, sharex="col", figsize=(10, 8), constrained_layout=True)
    for col, omega in enumerate([0.600, 0.765]):
        config = vt.Config(
            CHATTER,
            excitation__omega_ratio=omega,
            run__periods=periods,
            run__transient_periods=periods - 20,
            run__samples_per_period=2000,
        )
        run = vt.simulate(config)
        last = run.t >= run.t[-1] - 2 * config.period_s  # the last two periods
        t = run.t[last]
        power = run.summary["average_power_w"]
        axes[0, col].set_title(f"Ω = {omega:.3f}: P_a = {power * 1e6:.1f} µW")
        axes[0, col].plot(t, run.d[last, 0] * 1e3)
        axes[1, col].plot(t, run.d[last, 1] * 1e3, color="tab:orange")
        axes[2, col].plot(t, run.i[last] * 1e6, color="tab:green")
        axes[0, col].set_ylabel("D1 [mm]")
        axes[1, col].set_ylabel("D2 [mm]")
        axes[2, col].set_ylabel("I [µA]")
        axes[2, col].set_xlabel("time t [s]")
        impacts = run.events.kind == "impact"
        print(
            f"Ω = {omega:.3f}: {run.summary['impacts_per_period']:.2f} impacts/period, "
            f"{int(impacts.sum())} impacts, {run.summary['chatter_sequences']} chatter sequences, "
            f"average power {power * 1e6:.2f} µW"
        )
    fig.suptitle("Chatter case (Fig. 22): gaps and current over the last two periods")
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
