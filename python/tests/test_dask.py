"""vibrotribo.dask.sweep on a LocalCluster (worker processes, so configurations and results
are pickled) returns exactly what the serial sweep returns."""

import pytest

import vibrotribo as vt
import vibrotribo.dask

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as c:
        yield c


def test_dask_sweep_equals_the_serial_sweep(client):
    config = vt.Config(omega_ratio=0.6)
    values = vt.grid(0.4, 0.9, 23)
    kwargs = dict(transient=40, recorded=16)
    serial = vt.sweep(config, "omega_ratio", values, **kwargs)
    for chunk_size in (None, 1, 5):
        spread = vibrotribo.dask.sweep(client, config, "omega_ratio", values, chunk_size=chunk_size, **kwargs)
        assert spread == serial, f"chunk_size={chunk_size}"
    # A harvester's failing points and the mechanics alone as well.
    mech = dict(transient=20, recorded=8, mechanics_only=True)
    assert vibrotribo.dask.sweep(client, config, "mass_ratio", vt.grid(1, 4, 7), **mech) == vt.sweep(
        config, "mass_ratio", vt.grid(1, 4, 7), **mech
    )


def test_dask_sweep_refuses_continuation_and_bad_input(client):
    with pytest.raises(ValueError, match="continuation='up' cannot be spread"):
        vibrotribo.dask.sweep(client, None, "omega_ratio", [0.6, 0.7], continuation="up")
    with pytest.raises(KeyError, match="omega_ratoi"):
        vibrotribo.dask.sweep(client, None, "omega_ratoi", [0.6, 0.7])
    with pytest.raises(ValueError, match="excitation.omega_ratio"):
        vibrotribo.dask.sweep(client, None, "omega_ratio", [0.6, -0.7])


def test_dask_map_equals_the_serial_map(client):
    kwargs = dict(transient=30, recorded=12)
    xs, ys = vt.grid(0.6, 0.8, 3), vt.grid(1.0, 1.5, 4)
    serial = vt.map(vt.Config(), "omega_ratio", xs, "gap_ratio", ys, **kwargs)
    for chunk_size in (None, 1, 3):
        spread = vibrotribo.dask.map(client, vt.Config(), "omega_ratio", xs, "gap_ratio", ys,
                                     chunk_size=chunk_size, **kwargs)
        assert spread.summary == serial.summary, f"chunk_size={chunk_size}"


def test_dask_basins_equal_the_serial_basins(client):
    args = (vt.Config(), "run.initial_positions[0]", -0.03, 0.03, "run.initial_velocities[0]", -0.5, 0.5, (4, 3))
    kwargs = dict(transient=60, recorded=20, mechanics_only=True)
    serial = vt.basins(*args, **kwargs)
    spread = vibrotribo.dask.basins(client, *args, **kwargs)
    assert spread.basins == serial.basins and spread.attractors == serial.attractors
    assert spread.starts == serial.starts
    assert spread.settings["transient_periods"] == serial.settings["transient_periods"] == 60


def test_an_interrupt_while_waiting_cancels_the_submitted_tasks():
    """The waiting side: KeyboardInterrupt during gather cancels every future first."""

    class Client:
        cancelled = None

        def gather(self, futures):
            raise KeyboardInterrupt

        def cancel(self, futures, force=False):
            Client.cancelled = (list(futures), force)

    class Future:
        status = "finished"

        def done(self):
            return True

    futures = [Future(), Future(), Future()]
    with pytest.raises(KeyboardInterrupt):
        vibrotribo.dask._gather(Client(), futures)
    assert Client.cancelled == (futures, True)
