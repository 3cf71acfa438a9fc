"""pdyn.kin_data, pdyn.integrate_accel, pdyn.fuse: known truth from closed forms with seeded
noise, SciPy as an independent cross-check (make_smoothing_spline, cumulative_trapezoid), the
command's output for the same file, and located errors."""

import json
import math
import subprocess

import numpy as np
import pytest

import pdyn


def noisy_circle(sigma, seed, n=401, R=5.0, w=0.8):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.05
    x = R * np.cos(w * t) + sigma * rng.standard_normal(n)
    y = R * np.sin(w * t) + sigma * rng.standard_normal(n)
    return t, x, y


def test_smoothing_matches_scipy_make_smoothing_spline():
    """With λ given, pdyn's fitted values, first and second derivatives at the samples equal
    SciPy's smoothing spline (same penalty Σ(y − f)² + λ∫f''²) on uneven samples; with λ by
    GCV, the chosen λ agrees with SciPy's GCV choice."""
    interpolate = pytest.importorskip("scipy.interpolate")
    if not hasattr(interpolate, "make_smoothing_spline"):
        pytest.skip("SciPy without make_smoothing_spline")
    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0, 10, 300))
    x = np.sin(t) + 0.05 * rng.standard_normal(300)
    y = np.cos(0.7 * t) + 0.05 * rng.standard_normal(300)
    for lam in (1e-3, 0.1):
        r = pdyn.kin_data(t, x, y, lam=lam)
        s = interpolate.make_smoothing_spline(t, x, lam=lam)
        # Two independent solvers (Reinsch's banded system; SciPy's B-spline normal
        # equations) agree to ~1e-7 of the signal's amplitude (measured 5e-8 at λ = 0.1).
        np.testing.assert_allclose(r["x"], s(t), rtol=0, atol=1e-6)
        np.testing.assert_allclose(r["v_x"], s.derivative(1)(t), rtol=0, atol=1e-5)
        np.testing.assert_allclose(r["a_x"], s.derivative(2)(t), rtol=0, atol=1e-4)
    r = pdyn.kin_data(t, x, y)
    for name, data in (("x", x), ("y", y)):
        s = interpolate.make_smoothing_spline(t, data)
        fit = next(f for f in r.fits if f["column"] == name)
        assert fit["lambda_from"] == "gcv"
        # SciPy's λ is not exposed: compare the fitted curves, which agree when λ does
        # (measured 1.2e-5; a λ 10 % off moves them by ~1e-3).
        np.testing.assert_allclose(r[name], s(t), rtol=0, atol=1e-4)


def test_kin_data_recovers_circular_motion_within_the_band():
    R, w = 5.0, 0.8
    t, x, y = noisy_circle(0.02, 1)
    r = pdyn.kin_data(t, x, y)
    inside = (t > r.boundary) & (t < t[-1] - r.boundary)
    assert inside.sum() > 200
    for name, truth in (("speed", R * w), ("a_n", R * w * w)):
        err = np.abs(r[name][inside] - truth)
        assert np.mean(err <= 2 * r["se_" + name][inside]) >= 0.9, name
    assert r.velocity.shape == (401, 2)
    assert all(abs(f["sigma"] / 0.02 - 1) < 0.15 for f in r.fits)
    np.testing.assert_allclose(r["curvature"][inside].mean(), 1 / R, rtol=0.02)


def test_kin_data_from_a_file_equals_the_command(examples, pdyn_bin):
    path = examples / "data" / "track.csv"
    r = pdyn.kin_data(path)
    out = subprocess.run([pdyn_bin, "kin", "--data", str(path), "--json"], capture_output=True, text=True)
    cli = json.loads(out.stdout)
    for name in ("speed", "a_n", "v_x"):
        np.testing.assert_array_equal(r[name], np.array(cli["table"][name], dtype=float))
    assert r.fits[0]["lambda"] == cli["smoothing"][0]["lambda"]


def test_integrate_accel_matches_scipy_and_converges():
    integrate = pytest.importorskip("scipy.integrate")
    t = np.linspace(0, 6, 301)
    a = -1.69 * 2 * np.cos(1.3 * t)
    r = pdyn.integrate_accel(t, a, v0=0.0, x0=2.0, rule="trapezoid")
    v = integrate.cumulative_trapezoid(a, t, initial=0)
    np.testing.assert_allclose(r["v_x"], v, rtol=0, atol=1e-13)
    np.testing.assert_allclose(r["x"], 2.0 + integrate.cumulative_trapezoid(v, t, initial=0),
                               rtol=0, atol=1e-12)
    # Simpson: 4th order (the largest error over the record shrinks 16 times when the step
    # halves; the error at one instant may pass through zero).
    errs = []
    for n in (200, 400):
        t = np.linspace(0, 6, n + 1)
        r = pdyn.integrate_accel(t, -1.69 * 2 * np.cos(1.3 * t), v0=0.0, x0=2.0)
        errs.append(np.max(np.abs(r["x"] - 2 * np.cos(1.3 * t))))
    assert 14 < errs[0] / errs[1] < 18, errs


def test_integrate_accel_bias_and_error_growth():
    rng = np.random.default_rng(2)
    t = np.arange(2001) / 100.0
    a = 0.03 + 0.05 * rng.standard_normal(t.size)
    r = pdyn.integrate_accel(t, a, bias=(0.0, 2.0))
    ax = r.axes[0]
    assert ax["sigma_a_from"] == "quiet interval"
    assert abs(ax["bias_removed"] - 0.03) < 5 * ax["bias_se"]
    assert abs(r["x"][-1]) < 4 * r["sigma_x"][-1]
    with pytest.raises(pdyn.ModelError, match="quiet interval"):
        pdyn.integrate_accel(t, a, bias=(50.0, 60.0))


def test_fuse_beats_both_sensors():
    rng = np.random.default_rng(9)
    ta = np.arange(6001) / 100.0
    p = 3 * np.sin(0.4 * ta) + ta
    acc = -3 * 0.16 * np.sin(0.4 * ta) + 0.07 + 0.05 * rng.standard_normal(ta.size)
    tf = np.arange(60) + 0.25
    fixes = 3 * np.sin(0.4 * tf) + tf + 1.0 * rng.standard_normal(tf.size)
    r = pdyn.fuse(ta, acc, tf, fixes, covariance=True)
    err = np.sqrt(np.mean((r["x"] - p) ** 2))
    fix_err = np.sqrt(np.mean((np.interp(ta, tf, fixes) - p) ** 2))
    assert err < 0.5 * fix_err, (err, fix_err)
    assert abs(r.sigma_p - 1.0) < 0.3 and abs(r.sigma_a - 0.05) < 0.01
    assert r.covariance.shape == (1, ta.size, 3, 3)
    np.testing.assert_allclose(np.sqrt(r.covariance[0, :, 0, 0]), r["sd_x"])
    assert abs(r["bias_x"][3000] - 0.07) < 4 * r["sd_bias_x"][3000]


def test_fuse_files(examples):
    r = pdyn.fuse(examples / "data" / "imu.csv", fixes=examples / "data" / "gps.csv")
    assert r.names == ["x", "y"]
    t = r["t"]
    truth = 30 * np.sin(0.1 * t) + 2 * t
    assert np.sqrt(np.mean((r["x"] - truth) ** 2)) < 0.7


def test_bad_data_raise_located_errors(tmp_path):
    t = np.arange(10.0)
    x = np.sin(t)
    bad = x.copy()
    bad[4] = np.nan
    with pytest.raises(pdyn.ModelError, match="index 4") as e:
        pdyn.kin_data(t, bad, x)
    assert e.value.file == "x"
    tt = t.copy()
    tt[6] = tt[5]
    with pytest.raises(pdyn.ModelError, match="duplicate time"):
        pdyn.kin_data(tt, x, x)
    f = tmp_path / "bad.csv"
    f.write_text("t,x,y\n0,0,0\n1,oops,1\n")
    with pytest.raises(pdyn.ModelError) as e:
        pdyn.kin_data(f)
    assert (e.value.line, e.value.column) == (3, 3)
    assert "not a number" in str(e.value)
    f.write_text("t,x,y\n")
    with pytest.raises(pdyn.ModelError, match="header but no data rows"):
        pdyn.kin_data(f)
    with pytest.raises(pdyn.ModelError, match="no column named `q`"):
        pdyn.kin_data(tmp_path / "bad.csv", columns=["t", "x", "q"])
    with pytest.raises(pdyn.ParameterError):
        pdyn.integrate_accel(t, x, rule="euler")


def test_interp_matches_numpy_and_scipy():
    interpolate = pytest.importorskip("scipy.interpolate")
    rng = np.random.default_rng(8)
    t = np.sort(rng.uniform(0, 5, 40))
    y = np.sin(t) + 0.3 * rng.standard_normal(40)
    at = np.linspace(t[0], t[-1], 777)
    np.testing.assert_allclose(pdyn.interp(t, y, at), np.interp(at, t, y), rtol=0, atol=1e-13)
    np.testing.assert_allclose(pdyn.interp(t, y, at, kind="cubic"),
                               interpolate.CubicSpline(t, y, bc_type="natural")(at), rtol=0, atol=1e-11)
    np.testing.assert_allclose(pdyn.interp(t, y, at, kind="pchip"),
                               interpolate.PchipInterpolator(t, y)(at), rtol=0, atol=1e-12)
    assert pdyn.interp(t, y, t[3]) == pytest.approx(y[3])
    with pytest.raises(pdyn.ModelError, match="outside the data's time range"):
        pdyn.interp(t, y, [t[-1] + 1])


def test_a_parquet_file_from_pandas_reads_as_its_csv(tmp_path):
    """``pdyn.kin_data(path)`` and ``pdyn.read_csv`` take a Parquet file written by pandas
    (its default Snappy and Zstandard): the same numbers as the CSV pandas writes of the same
    frame, and a NaN located by row and column."""
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    t, x, y = noisy_circle(0.01, 7)
    frame = pd.DataFrame({"t": t, "x": x, "y": y, "note": ["ok"] * len(t)})
    frame.to_csv(tmp_path / "track.csv", index=False, float_format="%.17g")
    frame.to_parquet(tmp_path / "track.parquet", index=False)
    frame.to_parquet(tmp_path / "track_zstd.data", index=False, compression="zstd")
    from_csv = pdyn.kin_data(str(tmp_path / "track.csv"))
    for name in ["track.parquet", "track_zstd.data"]:
        names, tt, values = pdyn.read_csv(tmp_path / name)
        assert names == ["x", "y"]
        np.testing.assert_array_equal(tt, t)
        np.testing.assert_array_equal(values[0], x)
        got = pdyn.kin_data(str(tmp_path / name))
        for col in ["speed", "a_n", "curvature"]:
            np.testing.assert_array_equal(got[col], from_csv[col])
    bad = frame.copy()
    bad.loc[41, "y"] = float("nan")
    bad.to_parquet(tmp_path / "bad.parquet", index=False)
    with pytest.raises(pdyn.ModelError, match=r"row 42: missing value \(null\)"):
        pdyn.kin_data(str(tmp_path / "bad.parquet"))
