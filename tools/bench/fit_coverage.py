"""Are the fit's standard errors honest? (issue #24; figures in docs/identification.md)

The monitoring rig of tests/python/test_monitor_replicas.py: ROSS 2.3's clean
inertances of the paper system (8 x 400 lines, 100-399.25 Hz, 10000 rpm,
monitor_cases.Truth, cached in the temp directory by that test), eq. 19 noise
10 % / 1 % (test_monitor_drift._eq19, seeds 600000 + replica, the test's own
draws); kt, kr, ct fitted with librcb.fit(scale="complex", noise=(10, 1),
starts=1). The truth is librcb's fit of ROSS's clean inertances (the two codes
agree to 1e-6 of kt). Printed per parameter: the mean, sd and rms of
z = (value - truth) / se over the replicas, and how many 95 % intervals hold
the truth.

--linear N: the same for the linearised estimator (numpy, no fit): librcb's
FRFs and their central-difference sensitivities at the truth, the residuals
weighted as the library weights them, with the weights at the measured values
("e", the library before the reweighting at the model) or at the true values
("h", the ideal); then, on the fits' own draws, "h" again (what the fits should
match). Also the library's formula (J^T W J)^-1 against the sandwich with
eq. 19's full 2 x 2 covariance of each point.

  OPENBLAS_NUM_THREADS=1 LIBRCB_PATH=build/src/librcb.so PYTHONPATH=tools/python \\
    python tools/bench/fit_coverage.py --replicas 200 --linear 2000
"""

import argparse
import hashlib
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "python"))

import diag_cases as dc  # noqa: E402
import monitor_cases as mc  # noqa: E402
import test_monitor_drift as td  # noqa: E402
import test_monitor_replicas as tr  # noqa: E402

import librcb as rcb  # noqa: E402

P = tr.PARAMS
BA, BS = mc.NOISE[0] / 100, mc.NOISE[1] / 100


def clean():
    path = Path(tempfile.gettempdir()) / f"rcb_monitor_replicas-{tr._key()}.npz"
    if path.is_file():
        return np.load(path)["H0"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mc.Truth().inertance(mc.KT0, None)


def report(label, Z):
    Z = np.asarray(Z)
    print(f"{label} ({len(Z)}): mean {Z.mean(0).round(3)}, sd {Z.std(0, ddof=1).round(3)}, "
          f"rms {np.sqrt((Z ** 2).mean(0)).round(3)}, 95 % intervals holding the truth "
          f"{(abs(Z) < 1.959964).sum(0)}")


def fits(m, H0, star, R):
    Z, t0 = [], time.time()
    for rep in range(R):
        with td._meas(td._eq19(H0, 600000 + rep)) as ms:
            f = rcb.fit(m, ms, P, scale="complex", noise=mc.NOISE[:2], starts=1)
        v = np.array([p["value"] for p in f.params])
        se = np.array([p["stderr"] for p in f.params])
        f.model.close()
        Z.append((v - star) / se)
    report(f"librcb fits, {time.time() - t0:.0f} s", Z)


def linear(m, H0, R):
    def frf():
        return rcb.frf(m, dc.OUTS, [dc.IN], mc.FREQ_HZ, rpm=dc.RPM, kind="inertance")[:, :, 0].T

    h0 = frf()
    cols = []
    for name in P:
        v = m[name]
        m[name] = v * (1 + 1e-6)
        hp = frf()
        m[name] = v * (1 - 1e-6)
        hm = frf()
        m[name] = v
        cols.append(((hp - hm) / 2e-6).ravel())  # dH / d ln p
    D = np.array(cols).T
    h = h0.ravel()
    a = np.repeat(np.sqrt((abs(h0) ** 2).sum(1)) / h0.shape[1] * BS, h0.shape[1])
    keep = abs(h) >= 2 * a  # the layout drops points at the additive floor
    h, D, a = h[keep], D[keep], a[keep]
    n = h.size

    def weights(x):
        return (1 / np.sqrt(BA ** 2 * x.real ** 2 / 3 + a ** 2 / 6),
                1 / np.sqrt(BA ** 2 * x.imag ** 2 / 3 + a ** 2 / 6))

    def z(e, at):
        sr, si = weights(e if at == "e" else h)
        J = np.vstack([D.real * sr[:, None], D.imag * si[:, None]])
        y = np.concatenate([(e - h).real * sr, (e - h).imag * si])
        dp, *_ = np.linalg.lstsq(J, y, rcond=None)
        r = y - J @ dp
        return dp / np.sqrt(np.diag(r @ r / (2 * n - len(P)) * np.linalg.inv(J.T @ J)))

    sr, si = weights(h)
    J = np.vstack([D.real * sr[:, None], D.imag * si[:, None]])
    A = np.linalg.inv(J.T @ J)
    rho = BA ** 2 / 3 * h.real * h.imag * sr * si  # Re/Im correlation of a point
    meat = J.T @ J + (J[:n] * rho[:, None]).T @ J[n:] + (J[n:] * rho[:, None]).T @ J[:n]
    print("sandwich / formula standard errors:",
          (np.sqrt(np.diag(A @ meat @ A)) / np.sqrt(np.diag(A))).round(4))
    g = np.random.default_rng(5)
    for at in ("e", "h"):
        Z = []
        for _ in range(R):
            r1, r2, phi = g.uniform(-1, 1, n), g.uniform(-1, 1, n), g.uniform(0, 2 * np.pi, n)
            Z.append(z(h * (1 + BA * r1) + a * r2 * np.exp(1j * phi), at))
        report(f"linearised, weights at {at}", Z)
    return h0, keep, z


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--replicas", type=int, default=64, help="librcb fits (0.4 s each)")
    ap.add_argument("--linear", type=int, default=0, help="linearised replicas (1 ms each)")
    a = ap.parse_args()
    H0 = clean()
    ini = Path(tempfile.mkdtemp()) / "model.ini"
    ini.write_text(mc.model_ini())
    print(f"clean inertances {hashlib.sha256(H0.tobytes()).hexdigest()[:8]}: {H0.shape[0]} x "
          f"{H0.shape[1]} lines, {P}")
    with rcb.Model.from_ini(ini) as m:
        with td._meas(H0) as ms:
            f = rcb.fit(m, ms, P, scale="complex", noise=mc.NOISE[:2], starts=1)
        star = np.array([p["value"] for p in f.params])
        if a.linear:
            h0, keep, z = linear(f.model, H0, a.linear)
            report("linearised, weights at h, the fits' draws",
                   [z(td._eq19(h0, 600000 + rep).ravel()[keep], "h")
                    for rep in range(a.replicas)])
        f.model.close()
        if a.replicas:
            fits(m, H0, star, a.replicas)


if __name__ == "__main__":
    main()
