"""pdyn.study: designs, measures, local and Dask backends, Parquet checkpoints, resume,
probabilities. The Dask tests run on distributed.LocalCluster(n_workers=2, processes=True)
and are skipped when dask.distributed or pyarrow is missing."""

import math
import os
import signal

import numpy as np
import pytest

import pdyn
from pdyn.study import DesignError, Grid, Samples, Sets, Study, normal, uniform, lognormal

pd = pytest.importorskip("pandas")

V0, SD_V0 = 11.176, 1.0            # 25 mph, +-1 m/s
THETA, SD_THETA = math.radians(45), math.radians(5)
MEASURES = {"range": ("x", "final"), "top": ("z", "max")}


def kremlin(examples):
    return pdyn.Model.from_file(examples / "kremlin_stone.toml")


def kremlin_study(examples, chunk_size=250, out=None, n=2000):
    design = Samples(n, seed=2026, v0=normal(V0, SD_V0), theta=normal(THETA, SD_THETA))
    return Study(kremlin(examples), design, measures=MEASURES, chunk_size=chunk_size, out=out)


def closed_form_range(v0, theta, g=9.81, H=71.0):
    vz = v0 * np.sin(theta)
    return v0 * np.cos(theta) * (vz + np.sqrt(vz * vz + 2 * g * H)) / g


def test_local_study_is_the_same_for_any_chunk_size(examples):
    ref = kremlin_study(examples, chunk_size=2000).run().table
    assert len(ref) == 2000 and list(ref["sample"]) == list(range(2000))
    for cs in (333, 7):
        other = kremlin_study(examples, chunk_size=cs).run().table
        pd.testing.assert_frame_equal(ref, other, check_exact=True)
    np.testing.assert_allclose(ref["range"], closed_form_range(ref["v0"], ref["theta"]),
                               rtol=1e-8)
    assert (ref["status"] == 1).all() and not ref["drifted"].any()
    assert {"hits the ground.t", "hits the ground.x", "top", "drift.energy"} <= set(ref.columns)


def test_exceedance_probability_agrees_with_quadrature(examples):
    stats = pytest.importorskip("scipy.stats")
    from scipy import integrate, optimize
    res = kremlin_study(examples).run()
    p = res.probability("range > 40")
    assert p.n == 2000 and 0 < p.low < p.p < p.high < 1

    # P(range > 40) = int pdf(theta) P(v0 > v*(theta)) dtheta, range increasing in v0.
    def tail(theta):
        v_star = optimize.brentq(lambda v: closed_form_range(v, theta) - 40.0, 0.1, 100.0,
                                 xtol=1e-12)
        return stats.norm.pdf(theta, THETA, SD_THETA) * stats.norm.sf(v_star, V0, SD_V0)

    exact, _ = integrate.quad(tail, THETA - 8 * SD_THETA, THETA + 8 * SD_THETA,
                              epsabs=1e-12, limit=200)
    assert exact in p, (exact, p)
    # The interval is honest: its half-width is about 1.96 sqrt(p(1-p)/n).
    assert abs((p.high - p.low) / 2 - 1.96 * math.sqrt(exact * (1 - exact) / 2000)) < 0.003


def test_bad_designs_are_refused_before_anything_runs(examples, tmp_path):
    m = kremlin(examples)
    with pytest.raises(DesignError, match="neither a parameter"):
        Study(m, Samples(10, seed=1, nope=normal(0, 1))).run()
    with pytest.raises(DesignError, match="standard deviation"):
        Samples(10, seed=1, v0=normal(11, -1))
    with pytest.raises(DesignError, match="empty grid"):
        Grid(v0=[])
    with pytest.raises(DesignError, match="high < low"):
        uniform(2, 1).check("v0")
    with pytest.raises(DesignError, match="positive integer"):
        Samples(0, v0=normal(1, 1))
    # A distribution that gives the projectile a negative mass: refused, nothing written.
    drag = pdyn.Model.from_file(examples / "projectile_drag.toml")
    out = tmp_path / "never"
    study = Study(drag, Samples(200, seed=3, m=normal(1.0, 0.5)), out=str(out))
    with pytest.raises(DesignError, match="mass"):
        study.run()
    assert not out.exists()
    with pytest.raises(DesignError, match="unknown settings"):
        Study(m, Grid(v0=[10.0]), settings={"rtoll": 1e-3})
    with pytest.raises(pdyn.ModelError, match="nonsense"):
        Study(m, Grid(v0=[10.0]), measures={"r": ("nonsense +", "final")}).run()


def test_designs_grid_list_and_initial_conditions(examples):
    m = kremlin(examples)
    g = Study(m, Grid(v0=[10.0, 12.0], z=[50.0, 71.0, 100.0]), measures=MEASURES).run()
    assert len(g.table) == 6
    assert list(g.table["v0"]) == [10, 10, 10, 12, 12, 12]
    np.testing.assert_allclose(g.table["range"],
                               closed_form_range(g.table["v0"], THETA, H=g.table["initial.z"]),
                               rtol=1e-8)
    s = Study(m, Sets({"v0": [10.0, 12.0], "theta": [0.5, 0.6]}), measures=MEASURES).run()
    np.testing.assert_allclose(s.table["range"], closed_form_range(np.array([10.0, 12.0]),
                                                                   np.array([0.5, 0.6])),
                               rtol=1e-8)
    ln = Samples(100, seed=5, v0=lognormal(2.4, 0.1)).matrix()
    assert (ln > 0).all()
    pytest.importorskip("scipy.stats")
    for method in ("lhs", "sobol"):
        x = Samples(128, seed=5, method=method, v0=uniform(10, 12)).matrix()
        assert x.shape == (128, 1) and (10 <= x).all() and (x < 12).all()
        # Stratified: every 1/128 of the range holds one sample (Latin hypercube), Sobol
        # points are balanced in every dyadic interval.
        counts = np.histogram(x, bins=8, range=(10, 12))[0]
        assert (counts == 16).all(), counts


def need_dask():
    pytest.importorskip("pyarrow")
    return pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def cluster():
    distributed = need_dask()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as c:
        with distributed.Client(c) as client:
            yield client


def test_resume_runs_only_the_missing_chunks(examples, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    clean = kremlin_study(examples, chunk_size=200, out=str(tmp_path / "clean")).run()
    assert clean.chunks_run == 10 and clean.chunks_skipped == 0

    class Interrupted(Exception):
        pass

    def stop_after_three(done, total):
        if done == 3:
            raise Interrupted

    out = str(tmp_path / "resumed")
    with pytest.raises(Interrupted):
        kremlin_study(examples, chunk_size=200, out=out).run(on_chunk=stop_after_three)
    assert len([f for f in os.listdir(out) if f.endswith(".parquet")]) == 3
    again = kremlin_study(examples, chunk_size=200, out=out).run()
    assert again.chunks_skipped == 3 and again.chunks_run == 7
    pd.testing.assert_frame_equal(clean.table, again.table, check_exact=True)
    # A third run has nothing to do.
    assert kremlin_study(examples, chunk_size=200, out=out).run().chunks_run == 0
    files = sorted(f for f in os.listdir(out) if f.endswith(".parquet"))
    assert len(files) == 10 and not [f for f in os.listdir(out) if ".tmp" in f]
    meta = pdyn.study.read_metadata(os.path.join(out, files[0]))
    assert meta["model"] == kremlin(examples).source and meta["seed"] == 2026
    assert meta["pdyn_version"] == pdyn.__version__ and meta["design"]["kind"] == "samples"
    # A different design never reuses these chunks, nor shares their folder: reading the
    # folder as one dataset must never mix two studies.
    other = Study(kremlin(examples), Samples(2000, seed=7, v0=normal(V0, SD_V0)),
                  measures=MEASURES, chunk_size=200, out=out)
    with pytest.raises(pdyn.study.OutputFolderError, match="another study"):
        other.run()
    assert pq.read_table(os.path.join(out, files[0])).num_rows == 200
    folder = pd.read_parquet(out)
    assert len(folder) == 2000 and folder["sample"].is_unique
    pd.testing.assert_frame_equal(folder.sort_values("sample", ignore_index=True),
                                  clean.table.sort_values("sample", ignore_index=True),
                                  check_exact=True, check_like=True)
    # A manifest that is not JSON is a clear error, not a JSONDecodeError.
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / pdyn.study.MANIFEST).write_text("{not json")
    with pytest.raises(pdyn.study.OutputFolderError, match="cannot be read"):
        Study(kremlin(examples), Samples(20, seed=7, v0=normal(V0, SD_V0)),
              measures=MEASURES, chunk_size=200, out=str(bad)).run()
    other.out = str(tmp_path / "other")
    assert other.run().chunks_run == 10
    # A folder with result files of another study and no manifest (older pdyn) is refused
    # too.
    os.remove(os.path.join(out, pdyn.study.MANIFEST))
    with pytest.raises(pdyn.study.OutputFolderError, match="result files of another study"):
        Study(kremlin(examples), Samples(2000, seed=7, v0=normal(V0, SD_V0)),
              measures=MEASURES, chunk_size=200, out=out).run()


def test_dask_cluster_equals_local_bit_for_bit_for_any_chunk_size(examples, cluster):
    ref = kremlin_study(examples, chunk_size=2000).run().table
    for cs in (2000, 250, 13):
        on_cluster = kremlin_study(examples, chunk_size=cs).run(client=cluster)
        assert on_cluster.chunks_run == math.ceil(2000 / cs)
        pd.testing.assert_frame_equal(ref, on_cluster.table, check_exact=True)


def test_dask_worker_killed_mid_study_loses_nothing(examples, cluster, tmp_path):
    ref = kremlin_study(examples, chunk_size=100).run().table
    killed = []

    def kill_a_worker(done, total):
        if done == 2 and not killed:
            pids = cluster.run(os.getpid)
            pid = sorted(pids.values())[0]
            os.kill(pid, signal.SIGKILL)
            killed.append((pid, done, total))

    res = kremlin_study(examples, chunk_size=100, out=str(tmp_path)).run(
        client=cluster, on_chunk=kill_a_worker, _delay=0.25)
    assert killed and killed[0][1] < killed[0][2], "the worker must die mid-study"
    t = res.table
    assert sorted(t["sample"]) == list(range(2000))  # every sample exactly once
    pd.testing.assert_frame_equal(ref, t, check_exact=True)
    cluster.wait_for_workers(2, timeout=60)


def test_cli_runs_a_study_file_and_resumes(examples, tmp_path, capsys):
    pytest.importorskip("pyarrow")
    spec = tmp_path / "study.toml"
    spec.write_text(
        'chunk_size = 100\nprobabilities = ["range > 40"]\n'
        '[design]\nkind = "samples"\nn = 300\nseed = 1\n'
        f'variables.v0 = {{ dist = "normal", mean = {V0}, sd = {SD_V0} }}\n'
        '[measures]\nrange = { of = "x", stat = "final" }\n')
    out = tmp_path / "out"
    args = [str(examples / "kremlin_stone.toml"), "--design", str(spec), "--out", str(out),
            "--no-progress"]
    assert pdyn.study.main(args) == 0
    text = capsys.readouterr().out
    assert "300 runs in 3 chunks (3 run now, 0 already" in text and "P(range > 40)" in text
    assert pdyn.study.main(args) == 0
    assert "(0 run now, 3 already" in capsys.readouterr().out
    bad = tmp_path / "bad.toml"
    bad.write_text('[design]\nkind = "grid"\nvariables.v0 = []\n')
    assert pdyn.study.main([args[0], "--design", str(bad), "--out", str(out)]) == 2
    assert "empty grid" in capsys.readouterr().err


def test_grid_as_xarray_plot_and_progress(examples):
    m = kremlin(examples)
    res = Study(m, Grid(v0=[10.0, 11.0, 12.0], theta=[0.6, 0.7]), measures=MEASURES).run(
        progress=True)
    assert res.chunks_run == 1 and len(res.table) == 6
    xr = pytest.importorskip("xarray")
    ds = res.to_xarray()
    assert isinstance(ds, xr.Dataset) and ds["range"].shape == (3, 2)
    assert ds["range"].sel(v0=11.0, theta=0.7).item() == \
        res.table.query("v0 == 11.0 and theta == 0.7")["range"].item()
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    ax = res.plot("range", bins=3)
    assert ax.get_xlabel() == "range"
    ens = m.ensemble(params={"v0": np.linspace(10, 12, 40)}, progress=True)
    np.testing.assert_array_equal(ens.final, m.ensemble(params={"v0": np.linspace(10, 12, 40)}).final)
