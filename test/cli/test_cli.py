#!/usr/bin/env python3
"""Tests of the `hunting` command-line tool against MODEL.md's published numbers and independent checks.

Usage: test_cli.py PATH_TO_HUNTING SOURCE_DIR. Prints "PASS name" / "FAIL name" per test (counted by scripts/test).
"""
import csv
import io
import json
import math
import os
import subprocess
import struct
import sys
import tempfile
import zlib

HUNTING = sys.argv[1]
SRC = sys.argv[2]
failures = 0


def run(*args, ok=True):
    p = subprocess.run([HUNTING, *args], capture_output=True, text=True, timeout=120)
    if ok and p.returncode != 0:
        raise AssertionError(f"hunting {' '.join(args)} exited {p.returncode}: {p.stderr}")
    return p


def run_json(*args):
    return json.loads(run(*args).stdout)


def write_file(d, name, text):
    """text into d/name; the path."""
    path = os.path.join(d, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def close(x, ref, tol, what):
    if not abs(x - ref) <= tol:
        raise AssertionError(f"{what} = {x!r}, expected {ref!r} +- {tol}")


def test_critical_published_speeds():
    # MODEL.md section 6, lambda = 0.1271
    for kx, ky, ref in [(8.96, 8.96, 536.634923), (6.96, 8.96, 476.872437), (4.96, 8.96, 428.155705),
                        (2.96, 8.96, 384.701298), (8.96, 2.96, 554.296633), (8.96, 14.96, 565.303816),
                        (8.96, 20.96, 635.487135)]:
        out = run_json("critical", "--kx", str(kx), "--ky", str(ky), "--conicity", "0.1271")
        close(out["v_crit_kmh"], ref, 1e-3, f"v_crit_kmh kx={kx} ky={ky}")
    out = run_json("critical", "--kx", "8.96", "--ky", "8.96", "--conicity", "0.1271")
    eig = sorted(out["eigenvalues"], key=lambda e: (e[0], e[1]))
    refs = sorted([[-61.5026, 90.8747], [-61.5026, -90.8747], [0.0, 89.7127], [0.0, -89.7127]])
    for e, r in zip(eig, refs):
        close(e[0], r[0], 1e-3, "Re eigenvalue")
        close(e[1], r[1], 1e-3, "Im eigenvalue")
    close(out["frequency_hz"], 89.7127 / (2 * math.pi), 1e-4, "frequency_hz")


def test_critical_default_vehicle_and_config_file():
    # MODEL.md section 7: default vehicle Hopf at 517.618 km/h; the shipped file gives the same.
    close(run_json("critical")["v_crit_kmh"], 517.618, 6e-4, "default v_crit_kmh")
    cfg = os.path.join(SRC, "config", "crh380_default.yaml")
    close(run_json("critical", "--config", cfg)["v_crit_kmh"], 517.618, 6e-4, "config file v_crit_kmh")
    # MODEL.md section 6, nonlinear Hopf speeds (Ky = 10.96)
    for kx, ref in [(9.1, 527.4349), (9.7, 544.3795), (9.9, 550.3513)]:
        close(run_json("critical", "--kx", str(kx), "--ky", "10.96")["v_crit_kmh"], ref, 1e-3, f"Hopf kx={kx}")
    # the same through getopt_long's other spellings: --name=value and an unambiguous prefix (--conic for --conicity)
    close(run_json("critical", "--kx=9.7", "--ky=10.96")["v_crit_kmh"], 544.3795, 1e-3, "Hopf --kx=9.7")
    close(run_json("critical", "--kx", "8.96", "--ky", "8.96", "--conic", "0.1271")["v_crit_kmh"], 536.634923, 1e-3,
          "Hopf --conic 0.1271")


def test_critical_conicity_inverts_critical_speed():
    out = run_json("critical-conicity", "--v", "536.634923", "--kx", "8.96", "--ky", "8.96")
    close(out["conicity_crit"], 0.1271, 1e-7, "conicity_crit at V0")


def test_eig_stability_flips_at_critical_speed():
    below = run_json("eig", "--v", "517.0")
    above = run_json("eig", "--v", "518.2")
    assert below["stable"] is True and above["stable"] is False, (below, above)
    assert max(e[0] for e in below["eigenvalues"]) < 0 < max(e[0] for e in above["eigenvalues"])


def test_simulate_csv_is_consistent():
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "sim.csv")
        run("simulate", "--v", "543", "--x0", "0.001,0.001,0.006,0.06", "--t", "1", "--dt-out", "0.0001",
            "--out", path)
        with open(path) as f:
            rows = list(csv.DictReader(f))
    assert len(rows) == 10001, len(rows)
    assert list(rows[0].keys()) == ["t_s", "y_m", "dy_mps", "psi_rad", "dpsi_radps", "accel_lat_mps2"]
    close(float(rows[0]["y_m"]), 0.001, 0, "initial y")
    # Independent checks: dy/dt column against central differences of y, and the acceleration column against
    # central differences of dy/dt (the model's own derivatives must agree with its trajectory).
    h = 0.0001
    worst_v = worst_a = 0.0
    for i in range(1, len(rows) - 1):
        dy = (float(rows[i + 1]["y_m"]) - float(rows[i - 1]["y_m"])) / (2 * h)
        worst_v = max(worst_v, abs(dy - float(rows[i]["dy_mps"])) / 2.0)
        acc = (float(rows[i + 1]["dy_mps"]) - float(rows[i - 1]["dy_mps"])) / (2 * h)
        worst_a = max(worst_a, abs(acc - float(rows[i]["accel_lat_mps2"])) / 500.0)
    assert worst_v < 2e-3 and worst_a < 2e-2, (worst_v, worst_a)


def test_simulate_linear_decays_below_critical_speed():
    # Below the linear critical speed the linear model decays at the rate of its least damped eigenvalue.
    out = run("simulate", "--linear", "--v", "450", "--x0", "0.001,0,0,0", "--t", "3", "--dt-out", "0.01").stdout
    rows = list(csv.DictReader(io.StringIO(out)))
    sigma = max(e[0] for e in run_json("eig", "--v", "450")["eigenvalues"])
    peak_late = max(abs(float(r["y_m"])) for r in rows if 2.5 <= float(r["t_s"]) <= 3.0)
    peak_early = max(abs(float(r["y_m"])) for r in rows if 0.5 <= float(r["t_s"]) <= 1.0)
    rate = math.log(peak_late / peak_early) / 2.0
    close(rate, sigma, 0.1 * abs(sigma), "decay rate vs least damped eigenvalue")


def test_lyapunov_linear_equals_eigenvalues():
    out = run_json("lyapunov", "--v", "400", "--conicity", "0.22", "--linear", "--t", "200")
    eig = run_json("eig", "--v", "400", "--conicity", "0.22")
    re = sorted((e[0] for e in eig["eigenvalues"]), reverse=True)
    for x, r in zip(out["exponents"], re):
        close(x, r, 0.03, "Lyapunov exponent vs Re(eigenvalue)")


def test_bad_input_gives_clear_errors():
    cases = [
        (["critical", "--kx", "-1"], "vehicle.kx_mn_m: must be > 0"),
        (["critical", "--kx", "abc"], "--kx: expected a finite number"),
        (["critical", "--conicity", "nan"], "--conicity: expected a finite number"),
        (["eig"], "--v KM/H (running speed) is required"),
        (["eig", "--v", "-5"], "--v must be > 0"),
        (["critical", "--bogus"], "unknown option '--bogus'"),
        (["critical", "--k", "9"], "ambiguous option '--k'"),
        (["critical", "--kx"], "option --kx needs a value MN/m"),
        (["eig", "--v", "450", "stray"], "unexpected argument 'stray'"),
        (["critical", "--config", "/nonexistent.yaml"], "cannot open"),
        (["simulate", "--v", "500", "--x0", "1,2,3"], "expected 4 comma-separated finite numbers"),
        (["simulate", "--v", "500", "--t", "-1"], "need --t > 0"),
        (["lyapunov", "--v", "500", "--method", "rk4"], "--method must be midpoint or dopri"),
        (["frobnicate"], "unknown command 'frobnicate'"),
        (["critical", "--conicity", "0"], "no critical speed"),
    ]
    for args, message in cases:
        p = run(*args, ok=False)
        assert p.returncode != 0, f"{args} exited 0"
        assert message in p.stderr, f"{args}: stderr {p.stderr!r} lacks {message!r}"
        assert p.stdout == "", f"{args}: printed to stdout on error: {p.stdout!r}"
    with tempfile.TemporaryDirectory() as d:
        bad = os.path.join(d, "bad.yaml")
        with open(os.path.join(SRC, "config", "crh380_default.yaml")) as f:
            text = f.read().replace("mass_kg: 1869", "mass_kg: -1869")
        with open(bad, "w") as f:
            f.write(text)
        p = run("critical", "--config", bad, ok=False)
        assert p.returncode != 0 and "vehicle.mass_kg: must be > 0" in p.stderr, p.stderr


def test_help_is_available():
    p = run("--help")
    assert "critical" in p.stdout and "simulate" in p.stdout
    # every command the main help lists (delta-r and equivalent-conicity once failed with exit 2), by --help and -h
    listed = p.stdout.split("commands:\n", 1)[1].split("\n\n", 1)[0].split("\n")
    cmds = [line.split()[0] for line in listed if line.strip()]
    assert {"critical", "estimate", "delta-r", "equivalent-conicity"} <= set(cmds), cmds
    for cmd in cmds:
        for flag in ("--help", "-h"):
            p = run(cmd, flag)
            assert p.returncode == 0 and p.stdout.startswith(f"usage: hunting {cmd}"), (cmd, flag, p.stdout, p.stderr)
    assert run(ok=False).returncode == 2


def test_sweep_rows_are_on_the_boundary():
    # a second method: at each row's speed and conicity the eigenvalues (dgeev) have a purely imaginary least
    # stable pair at the row's frequency
    out = run_json("sweep", "--from", "0.1", "--to", "0.3", "--n", "3")
    for row in out["rows"]:
        eig = run_json("eig", "--v", repr(row["v_crit_kmh"]), "--conicity", str(row["conicity"]))["eigenvalues"]
        re, im = eig[0]
        assert abs(re) <= 1e-6 * abs(im), (row, eig[0])
        close(abs(im) / (2 * math.pi), out["frequency_hz"], 1e-6, "frequency of the critical pair")
    # Critical speed falls with conicity (Klingel: frequency ~ v sqrt(lambda)).
    speeds = [r["v_crit_kmh"] for r in out["rows"]]
    assert speeds[0] > speeds[1] > speeds[2], speeds


def test_hopf_published_values():
    # MODEL.md section 6, Ky = 10.96: Hopf V to 1e-3 km/h, l1 to 4 significant digits
    for kx, v_ref, l1_ref in [(9.1, 527.4349, 7.4072), (9.7, 544.3795, 3.8482), (9.9, 550.3513, 2.7316)]:
        out = run_json("hopf", "--param", "v", "--kx", str(kx), "--ky", "10.96")
        close(out["v_kmh"], v_ref, 1e-3, f"Hopf v_kmh kx={kx}")
        close(out["l1"], l1_ref, 1e-4 * abs(l1_ref), f"l1 kx={kx}")
        assert out["kind"] == "subcritical", out
    out = run_json("hopf", "--param", "kx", "--v", "566.5220", "--ky", "10.96", "--from", "5", "--to", "15")
    assert len(out["points"]) == 1, out
    close(out["points"][0]["kx_mn_m"], 10.413634, 2e-5, "Hopf Kx at 566.522 km/h")


def test_hopf_curve_gh_point():
    out = run_json("hopf-curve", "--plane", "kx-v", "--ky", "10.96", "--from", "9.0", "--to", "10.7")
    assert len(out["gh"]) == 1, out["gh"]
    gh = out["gh"][0]
    close(gh["kx_mn_m"], 10.413634, 1e-5, "GH kx")
    close(gh["v_kmh"], 566.5220, 1e-3, "GH v")
    close(gh["l2"], -37.5146, 1e-4 * 37.5146, "GH l2")
    # l1 changes sign along the curve exactly once, at the GH point
    signs = [p["l1"] > 0 for p in out["points"]]
    assert signs[0] and not signs[-1] and sum(a != b for a, b in zip(signs, signs[1:])) == 1, signs


def test_cycles_published_folds():
    for kx, refs, amps in [(9.7, (542.478651, 543.209002), (4.17e-3, 5.98e-3)),
                           (9.9, (549.363387, 551.158654), (3.43e-3, 6.08e-3))]:
        out = run_json("cycles", "--kx", str(kx), "--ky", "10.96", "--amp-max", "0.0075")
        folds = out["folds"]
        assert len(folds) == 2, folds
        for f, ref, amp in zip(folds, refs, amps):
            close(f["v_kmh"], ref, 0.01, f"LPC kx={kx}")
            close(f["amplitude_m"], amp, 1e-5, f"LPC amplitude kx={kx}")
        assert [f["stable_side"] for f in folds] == ["upper", "lower"], folds
        # the branch between the folds is stable, outside it unstable (Floquet multipliers)
        for p in out["branch"]:
            inside = folds[0]["amplitude_m"] + 1e-5 < p["amplitude_m"] < folds[1]["amplitude_m"] - 1e-5
            outside = p["amplitude_m"] < folds[0]["amplitude_m"] - 1e-5 or p["amplitude_m"] > folds[1]["amplitude_m"] + 1e-5
            assert (inside and p["stable"]) or (outside and not p["stable"]) or not (inside or outside), p


def test_cycles_csv_and_refinement():
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "branch.csv")
        run("cycles", "--kx", "9.7", "--ky", "10.96", "--amp-max", "0.007", "--csv", "--out", path)
        with open(path) as f:
            rows = list(csv.DictReader(f))
    assert list(rows[0].keys())[:3] == ["v_kmh", "amplitude_m", "amplitude_psi_rad"], rows[0].keys()
    assert len(rows) > 20
    out = run_json("cycles", "--kx", "9.7", "--ky", "10.96", "--amp-max", "0.007", "--refine")
    assert all(r["persists"] and abs(r["change"]) < 1e-4 for r in out["refinement"]), out["refinement"]


def test_lpc_curve_cusp():
    out = run_json("lpc-curve", "--plane", "kx-v", "--ky", "10.96", "--from", "9.0", "--to", "10.7",
                   "--amp-max", "0.0075")
    assert len(out["cusps"]) == 1, out["cusps"]
    c = out["cusps"][0]
    close(c["kx_mn_m"], 9.416863, 1e-5, "CPC kx")
    close(c["v_kmh"], 532.4952, 1e-3, "CPC v")
    close(c["amplitude_m"], 5.47e-3, 1e-5, "CPC amplitude")
    # the curve passes through the one-parameter folds at Kx = 9.7 (542.478651 and 543.209002 km/h)
    pts = out["curves"][0]["points"]
    crossings = []
    for a, b in zip(pts, pts[1:]):
        if (a["kx_mn_m"] - 9.7) * (b["kx_mn_m"] - 9.7) <= 0 and a["kx_mn_m"] != b["kx_mn_m"]:
            t = (9.7 - a["kx_mn_m"]) / (b["kx_mn_m"] - a["kx_mn_m"])
            crossings.append(a["v_kmh"] + t * (b["v_kmh"] - a["v_kmh"]))
    crossings.sort()
    assert len(crossings) == 2, crossings
    close(crossings[0], 542.478651, 0.01, "LPC curve at Kx 9.7 (lower)")
    close(crossings[1], 543.209002, 0.01, "LPC curve at Kx 9.7 (upper)")


def test_bifurcation_bad_input():
    cases = [
        (["hopf", "--param", "mass"], "--param must be v, kx, ky or conicity"),
        (["hopf", "--param", "kx"], "--v KM/H (running speed) is required"),
        (["hopf", "--v", "500"], "--v is the parameter here"),
        (["hopf", "--v-min", "100"], "unknown option '--v-min'"),
        (["cycles", "--amp-max", "-1"], "need --v-min < --v-max, --amp-max >"),
        (["cycles", "--v-min", "600", "--v-max", "700"], "no Hopf point of the origin"),
        (["hopf-curve", "--plane", "xy"], "--plane must be kx-v, ky-v or kx-ky"),
        (["lpc-curve", "--from", "10", "--to", "9"], "need --from < --to"),
    ]
    for args, message in cases:
        p = run(*args, ok=False)
        assert p.returncode != 0, f"{args} exited 0"
        assert message in p.stderr, f"{args}: stderr {p.stderr!r} lacks {message!r}"


def sample_path():
    return os.path.join(SRC, "config", "conicity_samples", "crh380_worn_synthetic.csv")


def test_fit_conicity_sample_and_config():
    out = run_json("fit-conicity", sample_path(), "--terms", "2", "--symmetric")
    # the generating curve (MODEL.md's raw fit) has its peaks at +-9.88 mm with widths 1.46 mm and amplitude 0.70
    g = sorted(out["gaussians"], key=lambda t: t["center_m"])
    close(g[1]["center_m"], 0.00988, 3 * g[1]["center_m_stderr"] + 1e-5, "peak centre")
    close(g[1]["width_m"], 0.00146, 3 * g[1]["width_m_stderr"] + 2e-5, "peak width")
    assert out["n_points"] == 121 and out["dof"] == 117, out
    # noise sigma 0.0157 (MODEL.md's reported RMSE): the fit's RMSE is that within sampling error (~7% for 117 dof)
    close(out["rmse"], 0.0157, 0.25 * 0.0157, "rmse")
    assert 0.99 < out["r2"] < 1 and out["adj_r2"] < out["r2"], out
    with tempfile.TemporaryDirectory() as d:
        cfg = os.path.join(d, "fitted.yaml")
        out2 = run_json("fit-conicity", sample_path(), "--terms", "2", "--symmetric", "--write-config", cfg)
        crit = run_json("critical", "--config", cfg)
        close(crit["v_crit_kmh"], out2["hopf_kmh"], 1e-6, "Hopf speed of the written config")
        close(crit["conicity"], out2["conicity_at_zero"], 1e-12, "lambda(0) of the written config")
        # the same data in millimetres
        mm = os.path.join(d, "mm.csv")
        with open(sample_path()) as f, open(mm, "w") as g2:
            for line in f:
                if line.startswith("#"):
                    continue
                if line.startswith("y_m"):
                    g2.write("y_mm,conicity\n")
                    continue
                y, c = line.strip().split(",")
                g2.write(f"{float(y) * 1000:.4f},{c}\n")
        out3 = run_json("fit-conicity", mm, "--y-unit", "mm", "--terms", "2", "--symmetric")
        close(out3["sse"], out["sse"], 1e-9, "same fit from millimetres")


def test_fit_conicity_bad_input():
    with tempfile.TemporaryDirectory() as d:
        def write(name, text):
            return write_file(d, name, text)
        cases = [
            ([os.path.join(d, "missing.csv")], "cannot open"),
            ([write("hdr.csv", "y,lambda\n0,0.1\n")], "the header must be 'y_m,conicity'"),
            ([write("nan.csv", "y_m,conicity\n0.001,0.2\n0.002,nan\n")], "nan.csv:3: column 'conicity': expected a finite number"),
            ([write("cols.csv", "y_m,conicity\n0.001,0.2,7\n")], "cols.csv:2: expected 2 comma-separated columns"),
            ([write("few.csv", "y_m,conicity\n0.001,0.2\n0.002,0.3\n0.003,0.1\n"), "--terms", "2"],
             "3 points cannot determine 7 parameters"),
            ([write("flat.csv", "y_m,conicity\n" + "".join(f"{i * 1e-3},0.2\n" for i in range(20)))],
             "the conicity is constant"),
            ([sample_path(), "--terms", "9"], "--terms must be an integer in 1..8"),
            ([sample_path(), "--y-unit", "inch"], "--y-unit must be m or mm"),
            ([], "give the data file"),
        ]
        for args, message in cases:
            p = run("fit-conicity", *args, ok=False)
            assert p.returncode != 0, f"{args} exited 0"
            assert message in p.stderr, f"{args}: stderr {p.stderr!r} lacks {message!r}"


def test_tables_and_lookup():
    with tempfile.TemporaryDirectory() as d:
        tbl = os.path.join(d, "default.tbl")
        out = run_json("tables", "--out", tbl, "--conicity-min", "0.12", "--conicity-max", "0.16", "--n", "3")
        assert out["conicities"] == 3 and out["error_speed_kmh"] < 1.0, out
        look = run_json("table-lookup", "--table", tbl, "--conicity", "0.1358", "--v", "420")
        # Hopf speed: exact (the closed form at this conicity); basin edge: MODEL.md section 7, about 8.2 mm
        close(look["hopf_kmh"], run_json("critical", "--conicity", "0.1358")["v_crit_kmh"], 1e-6, "table Hopf")
        close(look["unstable_cycle_amplitude_m"], 8.2e-3, 0.1e-3, "edge at 420 km/h (MODEL.md: about 8.2 mm)")
        assert look["origin_stable"] and look["stable_cycle_amplitude_m"] > look["unstable_cycle_amplitude_m"]
        below = run_json("table-lookup", "--table", tbl, "--conicity", "0.1358", "--v", "200")
        assert below["unstable_cycle_amplitude_m"] is None, below  # no cycle below ~239.5 km/h
        # outside the table (issue #27 item 8): refused, not the end conicity's numbers in silence; --widen the
        # cautious reading: the Hopf speed the closed form's, the lowest cycle speed and the unstable cycle at or below
        # the cycle family computed at that conicity (hunting cycles: 226.8 km/h, 7.40 mm at 399.7 km/h)
        for c, v in (("0.20", "399.7"), ("0.10", "400"), ("0.1358", "100"), ("0.1358", "800")):
            p = run("table-lookup", "--table", tbl, "--conicity", c, "--v", v, ok=False)
            assert p.returncode == 1 and "refused" in p.stderr and p.stdout == "", (c, v, p.stderr)
        assert "outside the table's 0.12..0.16" in run("table-lookup", "--table", tbl, "--conicity", "0.2", "--v",
                                                        "400", ok=False).stderr
        wide = run_json("table-lookup", "--table", tbl, "--conicity", "0.20", "--v", "399.7", "--widen")
        family = run_json("cycles", "--conicity", "0.20", "--v-min", "150", "--v-max", "700", "--amp-max", "0.016")
        edge = min(a["amplitude_m"] + (399.7 - a["v_kmh"]) / (b["v_kmh"] - a["v_kmh"])
                   * (b["amplitude_m"] - a["amplitude_m"]) for a, b in zip(family["branch"], family["branch"][1:])
                   if (a["v_kmh"] - 399.7) * (b["v_kmh"] - 399.7) <= 0 and a["v_kmh"] != b["v_kmh"] and not a["stable"])
        close(wide["hopf_kmh"], run_json("critical", "--conicity", "0.20")["v_crit_kmh"], 1e-6, "widened Hopf")
        assert wide["widened"] and wide["conicity"] == 0.2 and wide["table_conicity"] == 0.16, wide
        assert wide["l1"] is None, wide  # not known outside the table (the end conicity's had been given)
        assert wide["lowest_cycle_kmh"] <= family["lowest_cycle_v_kmh"], (wide, family["lowest_cycle_v_kmh"])
        assert 0.8 * edge < wide["unstable_cycle_amplitude_m"] <= edge, (wide, edge)
        inside = run_json("table-lookup", "--table", tbl, "--conicity", "0.1358", "--v", "420", "--widen")
        assert inside == look, (inside, look)  # inside the table --widen is the lookup
        bad = os.path.join(d, "bad.tbl")
        with open(bad, "w") as f:
            f.write("hunting_monitor_boundary_table 1\nkx_mn_m 8.96\n")
        p = run("table-lookup", "--table", bad, "--conicity", "0.13", "--v", "300", ok=False)
        assert p.returncode != 0 and "line 2: expected 'ky_mn_m'" in p.stderr, p.stderr


def lines(text):
    return [json.loads(line) for line in text.splitlines() if line.strip()]


def test_simulate_streams_and_estimate_ramp_through_hopf():
    # A speed ramp 480 -> 530 km/h over 30 s through the Hopf speed (517.6 km/h) on a smooth irregular track, for a
    # vehicle whose conicity is known (a prior range of 0.1358 -+ 1e-5): the monitor says OK first (480 km/h is in
    # the bistable band, which is stated in the fields, not as a level), WATCH from 30 km/h below the Hopf interval
    # (517.618 -+ the table's stated error), WARN from 10 km/h below it, ALARM at the latest once the Hopf speed is
    # passed, and never shows margins without data. With the default prior (0.1358 -+ 0.03) the same run is WARN
    # from the start: the interval's lower end is the closed-form Hopf speed at 0.1658 (`hunting critical`).
    with tempfile.TemporaryDirectory() as d:
        acc, spd, tbl = (os.path.join(d, n) for n in ("a.csv", "s.csv", "t.tbl"))
        run("simulate", "--v", "480", "--v-end", "530", "--t", "30", "--irregularity", "0.01", "--dt-out", "0.0005",
            "--accel-out", acc, "--speed-out", spd, "--accel-noise", "0.05", "--out", os.devnull)
        with open(acc) as f:
            head = [next(f) for _ in range(3)]
        assert head[0].strip() == "t_s,accel_mps2" and len(open(acc).readlines()) == 60002, head
        run("tables", "--out", tbl, "--conicity-min", "0.12", "--conicity-max", "0.16", "--n", "3")
        known = os.path.join(d, "known.yaml")
        with open(known, "w") as f:
            f.write("alarm:\n  conicity_prior_low: 0.13579\n  conicity_prior_high: 0.13581\n")
        out = lines(run("estimate", "--accel", acc, "--speed", spd, "--table", tbl, "--every", "0.5",
                        "--monitor", known).stdout)
        prior = lines(run("estimate", "--accel", acc, "--speed", spd, "--table", tbl, "--every", "0.5").stdout)
    worn_hopf = json.loads(run("critical", "--conicity", "0.1658").stdout)["v_crit_kmh"]
    first = next(o for o in prior if o["level"] != "NO_DATA")
    assert first["level"] == "WARN" and first["reason_code"] == 5 and not first["conicity_from_estimate"], first
    close(first["hopf_kmh_low"], worn_hopf, 0.01, "the prior's lower end")
    assert len(out) >= 55, len(out)
    levels = [o["level"] for o in out]
    assert levels[1] == "OK" and out[1]["margin_lowest_cycle_kmh"] < 0, levels
    for level, below in (("WATCH", 30.0), ("WARN", 10.0)):
        first = next(o for o in out if o["level"] == level)
        close(first["speed_kmh"], first["hopf_kmh_low"] - below, 1.0, f"speed at the first {level}")
        close(first["hopf_kmh_low"], 517.618, 1.0, "lower end of the Hopf interval (MODEL.md section 7)")
    first_alarm = next(o for o in out if o["level"] == "ALARM")
    assert first_alarm["speed_kmh"] <= 517.618 + 3.0, first_alarm  # alarmed at the latest just past Hopf
    assert all(o["level"] == "ALARM" for o in out if o["speed_kmh"] >= 520.0), levels
    for o in out:
        assert all(v is None or (isinstance(v, (int, float)) and math.isfinite(v)) for v in o.values()
                   if not isinstance(v, (str, bool))), o
        if o["level"] != "NO_DATA":
            assert o["margin_hopf_kmh"] is not None and o["hopf_kmh"] is not None, o
    # the level changes carry reasons, and there are few of them (no chatter)
    changes = [o for o in out if o["level_changed"]]
    assert 1 <= len(changes) <= 4 and all(o["reason"] for o in changes), [(o["t_s"], o["level"]) for o in changes]


def test_estimate_bad_and_stale_input():
    with tempfile.TemporaryDirectory() as d:
        acc = os.path.join(d, "a.csv")
        tbl = os.path.join(d, "t.tbl")
        run("tables", "--out", tbl, "--conicity-min", "0.12", "--conicity-max", "0.16", "--n", "2")
        with open(acc, "w") as f:
            f.write("t_s,accel_mps2\n")
            for i in range(6000):
                t = i / 2000
                if 2000 <= i < 3000:
                    continue  # a 0.5 s dropout
                value = "nan" if i % 997 == 0 else "%.6f" % (2.0 * math.sin(2 * math.pi * 14 * t))
                f.write(f"{t:.4f},{value}\n")
        out = lines(run("estimate", "--accel", acc, "--v", "400", "--table", tbl, "--every", "0.25").stdout)
        assert out[-1]["rejected_samples"] == 6 and out[-1]["gaps"] == 1, out[-1]
        assert all(o["level"] != "NO_DATA" for o in out), [o["level"] for o in out]
        bad = os.path.join(d, "bad.csv")
        with open(bad, "w") as f:
            f.write("time,accel\n0,1\n")
        p = run("estimate", "--accel", bad, "--v", "400", "--table", tbl, ok=False)
        assert p.returncode != 0 and "the header must be 't_s,accel_mps2'" in p.stderr, p.stderr
        p = run("estimate", "--accel", acc, "--table", tbl, ok=False)
        assert p.returncode != 0 and "exactly one of --speed FILE or --v" in p.stderr, p.stderr
        mon = os.path.join(d, "m.yaml")
        with open(mon, "w") as f:
            f.write("estimator:\n  rms_limit: 3\n")
        p = run("estimate", "--accel", acc, "--v", "400", "--table", tbl, "--monitor", mon, ok=False)
        assert p.returncode != 0 and "estimator.rms_limit: unknown key" in p.stderr, p.stderr
        # found by fuzzing: huge buffer-sizing settings aborted with "double free or corruption"
        with open(mon, "w") as f:
            f.write("estimator:\n  tracking_time_s: 57646075230342348\n")
        p = run("estimate", "--accel", acc, "--v", "400", "--table", tbl, "--monitor", mon, ok=False)
        assert p.returncode == 1 and "tracking_time_s: must be in (0, 20]" in p.stderr, p.stderr
        # inputs that used to run without a word
        def write(name, text):
            return write_file(d, name, text)
        slow = write("slow.csv", "t_s,accel_mps2\n" + "".join(f"{i / 50:.3f},0.1\n" for i in range(500)))
        corrupt = write("corrupt.tbl", open(tbl).read().replace("hopf_kmh ", "hopf_kmh 0 x", 1)
                        .replace(" x", " junk ", 1))
        cases = [
            (["--accel", write("h.csv", "t_s,accel_mps2\n"), "--v", "400"], "no samples (only a header)"),
            (["--accel", write("n.csv", "t_s,accel_mps2\nnan,1\nnan,2\nnan,3\n"), "--v", "400"],
             "fewer than two samples with a finite time stamp"),
            (["--accel", slow, "--v", "400"], "sample rate is 50 Hz; 100..5000 Hz is supported"),
            (["--accel", acc, "--v", "-1"], "--v must be in (0, 1000] km/h"),
            (["--accel", acc, "--v", "400", "--kx", "9.7"], "not for this vehicle: table made for Kx 8.96"),
            (["--accel", acc, "--v", "400", "--table", corrupt], "line 4:"),
        ]
        # an offline run with no usable speed is an error, not a stream of NO_DATA that exits 0
        p = run("estimate", "--accel", acc, "--speed", write("hs.csv", "t_s,speed_kmh\n"), "--table", tbl, ok=False)
        assert p.returncode == 1 and "no samples (only a header)" in p.stderr and p.stdout == "", p.stderr
        p = run("estimate", "--accel", acc, "--speed", write("ns.csv", "t_s,speed_kmh\n0,nan\n1,-5\n2,nan\n"),
                "--table", tbl, ok=False)
        assert p.returncode == 1 and "no usable speed (3 rejected)" in p.stderr, p.stderr
        for args, message in cases:
            if "--table" not in args:
                args = args + ["--table", tbl]
            p = run("estimate", *args, ok=False)
            assert p.returncode == 1 and message in p.stderr and p.stdout == "", (args, p.stderr)
        # a table whose boundaries are implausible is refused, not read as OK
        with open(tbl) as f:
            text = f.read()
        head, _, rest = text.partition("conicity ")
        record, _, points = rest.partition("\n")
        words = record.split()
        words[words.index("hopf_kmh") + 1] = "0"
        words[words.index("lowest_kmh") + 1] = "-5"
        p = run("estimate", "--accel", acc, "--v", "300", "--table",
                write("zero.tbl", head + "conicity " + " ".join(words[0:]) + "\n" + points), ok=False)
        assert p.returncode == 1 and "hopf_kmh must be in (0, 3000]" in p.stderr, p.stderr


def test_estimate_last_line_counts_everything():
    # issue #27 item 8: the last line holds every input counter, rows refused after the last periodic line included
    # (the data end on a line's time, 3.0 s, then a row without a time and one out of order: the last line had said 0
    # refused); references: what this test wrote into the files
    with tempfile.TemporaryDirectory() as d:
        acc, spd = os.path.join(d, "a.csv"), os.path.join(d, "s.csv")
        n = 6001  # 0 .. 3.0 s at 2 kHz
        with open(acc, "w") as f:
            f.write("t_s,accel_mps2\n")
            f.write("".join(f"{i / 2000:.4f},{2.0 * math.sin(2 * math.pi * 14 * i / 2000):.6f}\n" for i in range(n)))
            f.write("nan,1.0\n2.5,1.0\n")  # refused: no time, out of order
        with open(spd, "w") as f:  # 0 .. 3.0 s at 10 Hz, one value and one time not a number, three rows after
            f.write("t_s,speed_kmh\n")  # the end (a row without a time had stopped the speeds after it: NO_DATA)
            f.write("".join(f"{i / 10:.1f},{'nan' if i == 5 else '400'}\n" + ("nan,400\n" if i == 10 else "")
                            for i in range(31)))
            f.write("3.5,400\nnan,400\n4.0,400\n")
        out = lines(run("estimate", "--accel", acc, "--speed", spd, "--table", shipped_table(), "--every", "0.5").stdout)
        last = out[-1]
        counts = {k: last[k] for k in ("accel_rows", "accel_samples", "rejected_samples", "rejected_nonfinite",
                                       "rejected_out_of_range", "rejected_out_of_order", "speed_rows",
                                       "speed_updates", "rejected_speeds", "speed_rows_unused")}
        assert counts == {"accel_rows": n + 2, "accel_samples": n, "rejected_samples": 2, "rejected_nonfinite": 1,
                          "rejected_out_of_range": 0, "rejected_out_of_order": 1, "speed_rows": 35,
                          "speed_updates": 32, "rejected_speeds": 2, "speed_rows_unused": 3}, counts
        close(last["t_s"], 3.0, 1e-9, "the last line at the last sample's time")
        assert last["level"] != "NO_DATA" and last["speed_valid"], last
        for key in ("gaps", "samples_lost", "rate_changes"):
            assert last[key] == 0, (key, last[key])


def split_recording(path, t_split, first, second, shift=0.0):
    """The rows of a t_s,... CSV before t_split into first, the others (their times + shift) into second."""
    with open(path) as f:
        head = next(f)
        with open(first, "w") as a, open(second, "w") as b:
            a.write(head)
            b.write(head)
            for line in f:
                t, rest = line.split(",", 1)
                if float(t) < t_split:
                    a.write(line)
                else:
                    b.write(f"{float(t) + shift!r},{rest}")


def test_estimate_state_survives_a_restart():
    # 120 s at 480 km/h (35 km/h below the Hopf speed, 517.6 km/h) on 10% of the low-disturbance track: the prior's
    # interval, 464.8-593.8 km/h, gives WARN at 480 km/h until the first full window (40 s) identifies the conicity.
    # The recording's first minute, run alone with --state-out, writes the state; the second minute, run with
    # --state-in, starts where the whole run is at 60 s: its first status has the identified interval of the whole
    # run at 60 s, and no line is a WARN from the prior. The file is the format state.h documents (its CRC-32 checked
    # with zlib's). Without the state the second minute starts from the prior (WARN); a foreign vehicle's state, a
    # stale one (the second minute 1000 s later on the same time line: memory_s is 900 s) and a damaged one are
    # refused with their reasons, the last restored from FILE.prev.
    with tempfile.TemporaryDirectory() as d:
        p = {n: os.path.join(d, n) for n in ("a.csv", "s.csv", "a1.csv", "s1.csv", "a2.csv", "s2.csv", "a3.csv",
                                              "s3.csv", "state")}
        run("simulate", "--v", "480", "--t", "120", "--irregularity", "0.1", "--dt-out", "0.0005", "--accel-out",
            p["a.csv"], "--speed-out", p["s.csv"], "--accel-noise", "0.05", "--out", os.devnull)
        for name in ("a", "s"):
            split_recording(p[f"{name}.csv"], 60.0, p[f"{name}1.csv"], p[f"{name}2.csv"])
            split_recording(p[f"{name}.csv"], 60.0, os.devnull, p[f"{name}3.csv"], shift=1000.0)
        table = shipped_table()

        def part(k, *extra):
            r = run("estimate", "--accel", p[f"a{k}.csv"], "--speed", p[f"s{k}.csv"], "--table", table, "--every",
                    "1", *extra)
            return lines(r.stdout), r.stderr
        whole = lines(run("estimate", "--accel", p["a.csv"], "--speed", p["s.csv"], "--table", table, "--every",
                          "1").stdout)
        at60 = [o for o in whole if o["t_s"] <= 60.0][-1]
        assert at60["conicity_from_estimate"] and at60["level"] != "WARN", at60
        assert at60["hopf_kmh_low"] <= 517.618 <= at60["hopf_kmh_high"], at60
        first, _ = part(1, "--state-out", p["state"])
        assert all("restored" not in o for o in first), first[0]
        with open(p["state"], "rb") as f:
            rec = f.read()
        version, length = struct.unpack("<II", rec[8:16])
        assert rec[:8] == b"HMSTATE\0" and version == 1 and length == len(rec) == 136 + 72 * at60["windows_used"], \
            (rec[:16], len(rec))
        assert struct.unpack("<I", rec[-4:])[0] == zlib.crc32(rec[:-4]), "CRC-32"
        assert os.path.exists(p["state"] + ".prev"), "the previous state is kept"
        second, err = part(2, "--state-in", p["state"])
        said = f"restored, age 0 s, {at60['windows_used']} window"
        assert said in err and second[0]["restored"].startswith(said), (err, second[0].get("restored"))
        o = second[0]
        assert o["conicity_from_estimate"] and o["level"] == at60["level"], o
        for key in ("hopf_kmh_low", "hopf_kmh_high", "hopf_kmh", "conicity_used", "warn_from_kmh"):
            close(o[key], at60[key], 1e-9 * abs(at60[key]), f"restored {key}")
        assert not any(o["level"] == "WARN" and o["conicity_from_prior"] for o in second), \
            [(o["t_s"], o["level"]) for o in second if o["level"] == "WARN"]
        assert all("restored" not in o for o in second[1:]), "only the first line says it"
        # the control: the second minute alone starts from the prior
        fresh, _ = part(2)
        assert fresh[0]["level"] == "WARN" and fresh[0]["conicity_from_prior"], fresh[0]
        # refused: another vehicle (lambda(0) 0.15), too old (the same time line 1000 s later), then damaged
        for k, extra, reason in ((2, ("--conicity", "0.15"), "written for another vehicle or other settings"),
                                 (3, (), "too old: age 1000 s on the time line, the margin's memory_s 900 s")):
            out, err = part(k, "--state-in", p["state"], *extra)
            assert reason in err and out[0]["restored"].startswith("not restored: ") and reason in out[0]["restored"], \
                (err, out[0].get("restored"))
            assert out[0]["level"] == "WARN" and out[0]["conicity_from_prior"], out[0]
        with open(p["state"], "wb") as f:
            f.write(rec[:100])
        out, err = part(2, "--state-in", p["state"])
        assert f"{p['state']}: truncated: 100 of {len(rec)} bytes" in err and "restored from " in err, err
        assert out[0]["conicity_from_estimate"], out[0]
        # the wall clock: run right after, the state is seconds old
        out, err = part(2, "--state-in", p["state"] + ".prev", "--state-clock", "wall")
        assert out[0]["restored"].startswith("restored, age ") and out[0]["conicity_from_estimate"], out[0]
        p_bad = run("estimate", "--accel", p["a2.csv"], "--speed", p["s2.csv"], "--table", table, "--state-every", "0",
                    ok=False)
        assert p_bad.returncode == 1 and "--state-every: state.period_s: must be in [0.1, 3600]" in p_bad.stderr
        p_bad = run("estimate", "--accel", p["a2.csv"], "--speed", p["s2.csv"], "--table", table, "--state-out",
                    os.path.join(d, "no", "such", "dir"), ok=False)
        assert p_bad.returncode == 1 and "--state-out: " in p_bad.stderr and "cannot create" in p_bad.stderr
    print(f"  state: at 60 s the whole run and the restored one [{at60['hopf_kmh_low']:.2f}, "
          f"{at60['hopf_kmh_high']:.2f}] ({at60['level']}), the fresh one {fresh[0]['level']} "
          f"[{fresh[0]['hopf_kmh_low']:.2f}, {fresh[0]['hopf_kmh_high']:.2f}]")


def test_estimate_streams_long_recordings():
    # 25 minutes at 2 kHz (3 million rows, 51 MB): read a row at a time, so the peak memory stays far below the file
    # (loading it would take 48 MB of doubles, twice that while growing); the last line is at the last sample
    with tempfile.TemporaryDirectory() as d:
        acc = os.path.join(d, "long.csv")
        n = 3_000_000
        with open(acc, "w") as f:
            f.write("t_s,accel_mps2\n")
            step = 100_000
            for start in range(0, n, step):
                f.write("".join(f"{i / 2000:.4f},{(i % 29) * 0.01:.2f}\n" for i in range(start, start + step)))
        # a fresh interpreter whose only child is the tool: its children's peak RSS is the tool's
        probe = ("import resource, subprocess, sys\n"
                 "p = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
                 "sys.stdout.write(p.stdout)\n"
                 "sys.stderr.write(str(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss))\n"
                 "sys.exit(p.returncode)\n")
        p = subprocess.run(["/usr/bin/python3", "-c", probe, HUNTING, "estimate", "--accel", acc, "--v", "300",
                            "--every", "300", "--table", shipped_table()], capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
        out = lines(p.stdout)
        peak_kb = int(p.stderr.strip().splitlines()[-1])
        close(out[-1]["t_s"], (n - 1) / 2000, 1e-9, "last line at the last sample")
        # (40 MB: below the 48 MB that loading would take at the least; the AddressSanitizer build's shadow memory and
        # quarantine of freed blocks add to the tool's own 15-20 MB: 31.9 MB seen under it)
        assert peak_kb < 40_000, f"peak RSS {peak_kb} kB for a 51 MB recording"


def test_equivalent_conicity_of_a_cone_with_unequal_radii():
    # delta-r = 2 y tan(gamma) + 0.3 mm, tan(gamma) = 0.05, over -10..10 mm: tan gamma_e = 0.05 at every amplitude
    # by both methods, the equilibrium at -0.3 / 0.1 = -3 mm, null where the oscillation leaves the data (beyond 7 mm
    # about -3 mm), the wavelength Klingel's 2 pi sqrt(e0 r0 / tan gamma); --csv-out gives fit-conicity's input
    with tempfile.TemporaryDirectory() as d:
        path, out = os.path.join(d, "dr.csv"), os.path.join(d, "con.csv")
        with open(path, "w") as f:
            f.write("y_mm,delta_r_mm\n")
            for k in range(-100, 101):
                f.write(f"{0.1 * k:.1f},{2 * 0.1 * k * 0.05 + 0.3:.6f}\n")
        klingel = 2 * math.pi * math.sqrt(0.75 * 0.46 / 0.05)
        for method in ("integration", "regression"):
            r = run_json("equivalent-conicity", "--delta-r", path, "--amplitudes", "1:8:0.5", "--method", method,
                         "--csv-out", out)
            assert r["method"] == method and r["points"] == 201, r
            close(r["equilibrium_mm"], -3.0, 1e-9, "equilibrium")
            close(r["conicity_3mm"], 0.05, 1e-8, f"{method}: tan gamma_e at 3 mm")
            for a, c, w in zip(r["amplitude_mm"], r["conicity"], r["wavelength_m"]):
                if a < 7.0:
                    close(c, 0.05, 1e-8, f"{method}: tan gamma_e at {a} mm")
                    close(w, klingel, 1e-6, f"{method}: wavelength at {a} mm")
                elif a > 7.0:
                    assert c is None and w is None, (method, a, c)
            with open(out) as f:
                rows = f.read().split()
            assert rows[0] == "y_mm,conicity" and len(rows) in (1 + 2 * 12, 1 + 2 * 13), rows[:3]
            assert float(rows[1].split(",")[0]) <= -6.5 and float(rows[-1].split(",")[0]) >= 6.5, rows[1]
            assert all(abs(float(x.split(",")[1]) - 0.05) < 1e-8 for x in rows[1:]), rows[:3]
    # bad files and options: one line on stderr, nothing on stdout
    with tempfile.TemporaryDirectory() as d:
        def write(name, text):
            return write_file(d, name, text)
        cases = [
            ([], "give the delta-r file"),
            (["--delta-r", write("h.csv", "y,dr\n0,0\n1,1\n2,2\n")], "the header must be 'y_mm,delta_r_mm'"),
            (["--delta-r", write("b.csv", "y_mm,delta_r_mm\n-1,-0.1\n1,0.1\n0,0\n")], "y must increase strictly"),
            (["--delta-r", write("f.csv", "y_mm,delta_r_mm\n-1,0.1\n0,0\n1,-0.1\n")], "no restoring equilibrium"),
            (["--delta-r", write("t.csv", "y_mm,delta_r_mm\n-1,-0.1\n1,0.1\n")], "at least 3 are needed"),
            (["--delta-r", write("n.csv", "y_mm,delta_r_mm\n-1,-0.1\n0,x\n1,0.1\n")], "n.csv:3"),
            (["--delta-r", write("ok.csv", "y_mm,delta_r_mm\n-1,-0.1\n0,0\n1,0.1\n"),
              "--amplitudes", "3:1:0.1"], "--amplitudes must be FROM:TO:STEP"),
            (["--delta-r", os.path.join(d, "ok.csv"), "--method", "fourier"], "--method must be integration or regression"),
            (["--delta-r", os.path.join(d, "ok.csv"), "--r0-mm", "-460"], "r0_m: must be in [0.1, 1]"),
        ]
        for args, message in cases:
            p = run("equivalent-conicity", *args, ok=False)
            assert p.returncode != 0 and message in p.stderr and p.stdout == "", (args, p.stderr, p.stdout)
            assert p.stderr.count("\n") == 1, p.stderr


def test_equivalent_conicity_en15302_reference_cases():
    # EN 15302 Annex E/F (test/cli/en15302): the integration method within the reference band at every amplitude
    # from 1 to 5 mm on all nine delta-r functions, symmetric, with unequal radii, with a dead zone (E4: tan gamma_e
    # 0 within +-1.7 mm) and two different wheels (E9)
    base = os.path.join(SRC, "test", "cli", "en15302")
    report = []
    for n in range(1, 10):
        r = run_json("equivalent-conicity", "--delta-r", os.path.join(base, f"E{n}_delta_r.csv"), "--amplitudes",
                     "1:5:0.1")
        with open(os.path.join(base, f"E{n}_reference.csv")) as f:
            ref = {round(float(a), 3): (float(t), float(hi), float(lo))
                   for a, t, hi, lo in (line.strip().split(",") for line in list(f)[1:])}
        worst = 0.0
        for a, c in zip(r["amplitude_mm"], r["conicity"]):
            t, hi, lo = ref[round(a, 3)]
            assert c is not None and lo - 1e-9 <= c <= hi + 1e-9, (n, a, c, t, lo, hi)
            worst = max(worst, abs(c - t) / max(hi - t, t - lo))
        close(r["conicity_3mm"], ref[3.0][0], 0.005, f"E{n} at 3 mm")
        report.append(f"E{n} {r['conicity_3mm']:.3f} ({worst:.2f} of the band)")
    print("  EN 15302 at 3 mm: " + "; ".join(report))


def test_delta_r_from_profiles_and_the_chain():
    # a cone of 0.05 on knife-edge rails (upright): delta-r = 2 s tan(gamma) exactly, the contacts at the tips; the
    # shipped synthetic pair (config/profiles: a 1:40 tread and a flange on a crowned head inclined 1:40): the tread's
    # equivalent conicity is its cone, 0.025, until the flange takes the contact (between 6 and 7 mm), and the chain
    # delta-r -> equivalent-conicity -> fit-conicity gives a vehicle YAML
    with tempfile.TemporaryDirectory() as d:
        wheel = write_file(d, "w.csv", "y_mm,z_mm\n" + "".join(f"{0.1 * k:.1f},{-(0.1 * k - 70) * 0.05:.6f}\n"
                                                               for k in range(0, 1401)))
        rail = write_file(d, "r.csv", "y_mm,z_mm\n-20,-50\n0,0\n20,-50\n")
        r = run_json("delta-r", "--wheel", wheel, "--rail", rail, "--inclination", "0", "--max-shift-mm", "8")
        assert len(r["y_mm"]) == 161, len(r["y_mm"])
        for y, dr, cl, cr in zip(r["y_mm"], r["delta_r_mm"], r["contact_left_mm"], r["contact_right_mm"]):
            close(dr, 2 * y * 0.05, 1e-9, f"delta-r at {y} mm")
            close(cl, 717.5 + 5.6, 1e-9, "left contact at the tip")
            close(cr, -(717.5 + 5.6), 1e-9, "right contact at the tip")
        prof = os.path.join(SRC, "config", "profiles")
        dr_csv, con_csv, yaml_out = (os.path.join(d, n) for n in ("dr.csv", "con.csv", "fitted.yaml"))
        run_json("delta-r", "--wheel", os.path.join(prof, "wheel_synthetic.csv"), "--rail",
                 os.path.join(prof, "rail_synthetic.csv"), "--out", dr_csv)
        e = run_json("equivalent-conicity", "--delta-r", dr_csv, "--csv-out", con_csv)
        by = dict(zip((round(a, 1) for a in e["amplitude_mm"]), e["conicity"]))
        for a in (1.0, 3.0, 6.0):
            close(by[a], 0.025, 1e-6, f"the 1:40 tread at {a} mm")
        assert by[7.0] > 0.1, by[7.0]
        # with the roll (--roll) on the symmetric pair: no roll at zero shift, delta-r odd in the shift, and the
        # wheelset rolls toward the side whose radius grew, by about delta-r / the contacts' distance
        rolled = run_json("delta-r", "--wheel", os.path.join(prof, "wheel_synthetic.csv"), "--rail",
                          os.path.join(prof, "rail_synthetic.csv"), "--roll", "--max-shift-mm", "5")
        mid = len(rolled["y_mm"]) // 2
        assert rolled["roll_included"] and abs(rolled["roll_rad"][mid]) < 1e-9, rolled["roll_rad"][mid]
        for k in range(1, mid + 1):
            close(rolled["delta_r_mm"][mid + k], -rolled["delta_r_mm"][mid - k], 1e-6, "odd delta-r with roll")
            dist = rolled["contact_left_mm"][mid + k] - rolled["contact_right_mm"][mid + k]
            close(rolled["roll_rad"][mid + k], rolled["delta_r_mm"][mid + k] / dist, 0.02 * abs(rolled["roll_rad"][mid + k]) + 1e-9,
                  "roll from delta-r")
        f = run_json("fit-conicity", con_csv, "--y-unit", "mm", "--terms", "2", "--symmetric",
                     "--write-config", yaml_out)
        assert abs(f["conicity_at_zero"] - 0.025) < 0.01 and os.path.getsize(yaml_out) > 100, f["conicity_at_zero"]
        # the plot of the chain (scripts/plot_eqcon) from the three outputs
        files = {}
        for name, args in (("contact.json", ["delta-r", "--wheel", os.path.join(prof, "wheel_synthetic.csv"), "--rail",
                                             os.path.join(prof, "rail_synthetic.csv")]),
                           ("eqcon.json", ["equivalent-conicity", "--delta-r", dr_csv]),
                           ("fit.json", ["fit-conicity", con_csv, "--y-unit", "mm", "--terms", "2", "--symmetric"])):
            files[name] = write_file(d, name, run(*args).stdout)
        p = subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts", "plot_eqcon"), files["contact.json"],
                            files["eqcon.json"], files["fit.json"], "--out", os.path.join(d, "chain")],
                           capture_output=True, text=True)
        assert p.returncode == 0 and os.path.getsize(os.path.join(d, "chain.png")) > 10000, p.stderr
        cases = [
            ([], "give the profiles"),
            (["--wheel", wheel, "--rail", write_file(d, "h.csv", "y,z\n0,0\n1,1\n2,2\n")], "the header must be 'y_mm,z_mm'"),
            (["--wheel", write_file(d, "b.csv", "y_mm,z_mm\n0,0\n2,0\n1,0\n"), "--rail", rail],
             "left wheel profile: y must increase strictly"),
            (["--wheel", wheel, "--rail", write_file(d, "f.csv", "y_mm,z_mm\n-20,-5\n0,0\n20,-5\n")],
             "does not reach 14 mm below the top"),
            (["--wheel", write_file(d, "n.csv", "y_mm,z_mm\n60,0.25\n70,0\n80,-0.25\n"), "--rail", rail],
             "does not lie over its rail"),
            (["--wheel", wheel, "--rail", rail, "--inclination", "3"], "--inclination must be 0"),
            (["--wheel", wheel, "--rail", rail, "--gauge-mm", "1300"], "gauge_m: must exceed"),
            (["--wheel", write_file(d, "n2.csv", "y_mm,z_mm\n60,0.25\n70,0\n80,-0.25\n"), "--rail", rail, "--roll"],
             "do not rest on both rails"),
        ]
        for args, message in cases:
            p = run("delta-r", *args, ok=False)
            assert p.returncode != 0 and message in p.stderr and p.stdout == "", (args, p.stderr, p.stdout)


def test_simulate_speed_profile():
    # --profile T:V,...: the speed stream follows it exactly (linear between the points, steady after the last); bad
    # profiles refused with one line
    with tempfile.TemporaryDirectory() as d:
        spd = os.path.join(d, "s.csv")
        run("simulate", "--profile", "0:400,4:400,5:450,8:450", "--t", "10", "--irregularity", "0.01",
            "--speed-out", spd, "--out", os.devnull)
        with open(spd) as f:
            rows = [tuple(map(float, line.split(","))) for line in list(f)[1:]]
        assert len(rows) >= 99, len(rows)
        for t, v in rows:
            ref = 400.0 if t <= 4.0 else 450.0 if t >= 5.0 else 400.0 + 50.0 * (t - 4.0)
            close(v, ref, 1e-9, f"profile speed at {t} s")
        for bad, message in (("0:400,4", "--profile must be T:V"), ("1:400,4:450", "times increasing from 0 s"),
                             ("0:400,4:-1", "speeds > 0 km/h")):
            p = run("simulate", "--profile", bad, "--t", "1", "--out", os.devnull, ok=False)
            assert p.returncode != 0 and message in p.stderr and p.stderr.count("\n") == 1, (bad, p.stderr)


def test_json_numbers_round_trip():
    # numbers are written in their shortest form that reads back as the same double: a configured 8.96 MN/m comes
    # out as 8.96, a whole speed without an exponent, and a computed critical speed with every digit it needs (the
    # printed value, read back, gives back the same eigenvalue pair on the boundary)
    out = run_json("critical", "--kx", "8.96", "--ky", "8.96")
    raw = run("critical", "--kx", "8.96", "--ky", "8.96").stdout
    assert '"kx_mn_m": 8.96,' in raw and out["kx_mn_m"] == 8.96, raw
    assert '"v_kmh": 400,' in run("eig", "--v", "400").stdout
    v = out["v_crit_kmh"]
    assert repr(v) in raw, (repr(v), raw)  # Python's repr is the shortest round-trip form too
    eig = run_json("eig", "--v", repr(v))["eigenvalues"][0]
    assert abs(eig[0]) < 1e-9 * abs(eig[1]), eig


def test_write_errors_are_failures():
    if not os.path.exists("/dev/full"):
        return
    for args in (["critical"], ["simulate", "--v", "300", "--t", "0.1", "--out", "/dev/full"],
                 ["simulate", "--v", "300", "--t", "0.1", "--out", "/dev/null", "--accel-out", "/dev/full"]):
        with open("/dev/full", "w") as full:
            p = subprocess.run([HUNTING, *args], stdout=full, stderr=subprocess.PIPE, text=True, timeout=60)
        assert p.returncode == 1 and "write" in p.stderr, (args, p.returncode, p.stderr)


def test_unbounded_work_is_refused():
    for args, message in [(["lyapunov", "--v", "300", "--h", "1e-300"], "at most 1e+09 steps"),
                          (["lyapunov", "--v", "300", "--renorm", "1e308"], "--renorm <= --t"),
                          (["tables", "--v-max", "1e308", "--out", "/dev/null"], "--v-max <= 3000"),
                          (["simulate", "--v", "300", "--seed", "1e308"], "whole --seed in 0..2^53")]:
        p = run(*args, ok=False)
        assert p.returncode == 1 and message in p.stderr, (args, p.stderr)


# ---- the monitor on recordings of a second, independent simulator (../shared/scenarios/independent_sim.py: its own
# RK4 integrator at the sensor rate, its own track spectrum entering the wheel-rail terms, a 1 kHz accelerometer with
# 0.2 m/s^2 noise, a noisy 100 Hz speed signal). Recordings are cached in $HM_SIM_CACHE (scripts/test sets it) so the
# sanitizer run reuses them.

def independent_sim():
    path = os.environ.get("HM_INDEPENDENT_SIM") or os.path.join(SRC, "..", "shared", "scenarios", "independent_sim.py")
    if not os.path.exists(path):
        raise AssertionError(f"the independent simulator is not at {path} (set HM_INDEPENDENT_SIM)")
    return path


def recording(name, *args):
    """(accel, speed, truth) of an independent-simulator run, made once."""
    cache = os.environ.get("HM_SIM_CACHE") or os.path.join(tempfile.gettempdir(), "hm_sim_cache")
    os.makedirs(cache, exist_ok=True)
    truth = os.path.join(cache, name + "_truth.json")
    if not os.path.exists(truth):
        subprocess.run(["/usr/bin/python3", independent_sim(), *args, "--out", cache, "--name", name],
                       check=True, capture_output=True, timeout=600)
    with open(truth) as f:
        return os.path.join(cache, name + "_accel.csv"), os.path.join(cache, name + "_speed.csv"), json.load(f)


def shipped_table():
    return os.path.join(SRC, "config", "crh380_default.tbl")


def estimate_lines(acc, spd, every, *extra):
    return lines(run("estimate", "--accel", acc, "--speed", spd, "--table", shipped_table(), "--every", str(every),
                     *extra).stdout)


def model_decay_rate(v_kmh, conicity):
    """Real part of the least damped pair of the linear model (dgeev): the reference."""
    return run_json("eig", "--v", str(v_kmh), "--conicity", str(conicity))["eigenvalues"][0][0]


def test_independent_sim_decay_rates():
    # 45 s at a steady speed (the first 5 s of the simulator's start-up included), five seeds each: the decay rate
    # the monitor identifies is within max(25%, 0.3 1/s) of the model's eigenvalue, or within 3 of its error (its
    # standard error, the margin's systematic 5% and the window's 1/T: a 40 s window cannot know a decay rate near
    # the Hopf speed better than about sqrt(2 |sigma| / T), 0.22 1/s at 500 km/h, so 0.3 alone is 1.4 of that and a
    # seed sat on it: -0.68 and, after issue #26's fit, -0.63 +- 0.14 for -0.98); the five seeds' mean within 3
    # standard errors of their mean (and 0.15 1/s) of the eigenvalue: no bias
    report = []
    for v in (420, 460, 500, 510):
        truth = model_decay_rate(v, 0.1358)
        got, ses = [], []
        for seed in range(1, 6):
            acc, spd, _ = recording(f"const{v}_s{seed}", "--profile", f"const:{v}", "--t", "45", "--seed", str(seed))
            last = estimate_lines(acc, spd, 45)[-1]
            assert last["mode_valid"], (v, seed, last)
            sigma, se = last["decay_rate_1_s"], last["decay_rate_se_1_s"]
            err = math.hypot(se, 0.05 * abs(sigma) + 1.0 / 40.0)
            got.append(sigma)
            ses.append(err)
            close(sigma, truth, max(0.25 * abs(truth), 0.3, 3.0 * err), f"decay rate at {v} km/h seed {seed}")
            assert last["level"] != "ALARM", (v, seed, last["reason"])
        mean = sum(got) / len(got)
        se_mean = math.sqrt(sum(e * e for e in ses)) / len(ses)
        close(mean, truth, max(3.0 * se_mean, 0.15), f"mean decay rate at {v} km/h")
        report.append(f"{v} km/h: {min(got):.2f}..{max(got):.2f}, mean {mean:.2f} (model {truth:.2f})")
    print("  independent simulator, decay rates: " + "; ".join(report))


def test_independent_sim_worn_and_new_wheels():
    # 120 s at three steady speeds below the Hopf speed: the Hopf speed shown within 10 km/h of the truth (the
    # closed form at the true conicity) with an interval covering it; never ALARM on these stable vehicles
    cases = [("worn", 0.16, "steps:420@40,440@40,455@40", 1), ("worn", 0.16, "steps:420@40,440@40,455@40", 2),
             ("new", 0.12, "steps:480@40,500@40,520@40", 11), ("new", 0.12, "steps:480@40,500@40,520@40", 12)]
    report = []
    for kind, conicity, profile, seed in cases:
        acc, spd, truth = recording(f"{kind}_s{seed}", "--profile", profile, "--lambda0", str(conicity), "--t", "120",
                                    "--seed", str(seed))
        assert truth["t_hunt_3mm"] is None, truth
        hopf = run_json("critical", "--conicity", str(conicity))["v_crit_kmh"]
        out = estimate_lines(acc, spd, 1)
        last = out[-1]
        assert last["conicity_from_estimate"] and last["windows_used"] >= 2, last
        close(last["hopf_kmh"], hopf, 10.0, f"{kind} seed {seed}: Hopf speed shown")
        assert last["hopf_kmh_low"] <= hopf <= last["hopf_kmh_high"], (hopf, last["hopf_kmh_low"], last["hopf_kmh_high"])
        assert not any(o["level"] == "ALARM" for o in out), [(o["t_s"], o["reason"]) for o in out if o["level"] == "ALARM"]
        report.append(f"{kind} {seed}: {last['hopf_kmh']:.1f} [{last['hopf_kmh_low']:.1f}, {last['hopf_kmh_high']:.1f}]"
                      f" (true {hopf:.1f})")
    print("  independent simulator, Hopf speeds: " + "; ".join(report))


def test_independent_sim_ramp_through_hopf():
    # 505 -> 535 km/h at 0.5 km/h/s: no ALARM below 515 km/h unless the wheelset is already hunting (the track can
    # kick it over the unstable cycle inside the bistable band: then no ALARM earlier than 1 s before it passes 3 mm);
    # ALARM no later than 1 s after it passes 3 mm
    for seed in (21, 22, 23):
        acc, spd, truth = recording(f"ramp_s{seed}", "--profile", "ramp:505:0.5", "--t", "60", "--seed", str(seed))
        t3 = truth["t_hunt_3mm"]
        assert t3 is not None, truth
        out = estimate_lines(acc, spd, 0.05)
        first = next(o for o in out if o["level"] == "ALARM")
        assert first["t_s"] <= t3 + 1.0, (seed, first["t_s"], t3)
        assert first["speed_kmh"] >= 515.0 or first["t_s"] >= t3 - 1.0, (seed, first["speed_kmh"], first["t_s"], t3)


def test_independent_sim_sample_rates():
    # one run recorded at 500 Hz, 1 kHz and 2 kHz, read with the shipped settings (2 kHz expected): the same amplitude
    # (within 10%) and frequency (within 1%), the other rates reported as mismatches
    mon = os.path.join(SRC, "config", "monitor.yaml")
    got = {}
    for fs in (500, 1000, 2000):
        acc, spd, _ = recording(f"rate{fs}", "--profile", "const:505", "--t", "20", "--seed", "31", "--fs", str(fs))
        last = estimate_lines(acc, spd, 20, "--monitor", mon)[-1]
        assert last["sample_rate_mismatch"] == (fs != 2000), (fs, last["sample_rate_hz"])
        close(last["sample_rate_hz"], fs, 0.01 * fs, "measured rate")
        got[fs] = last
    for fs in (500, 1000):
        close(got[fs]["amplitude_m"], got[2000]["amplitude_m"], 0.1 * got[2000]["amplitude_m"], f"amplitude at {fs} Hz")
        close(got[fs]["frequency_hz"], got[2000]["frequency_hz"], 0.01 * got[2000]["frequency_hz"], f"frequency at {fs} Hz")


def bogie_matrix(v, lam, kx=8.96e6, ky=8.96e6, ratio=1.351186, ksy=2.5e5, csy=3e4):
    """The linearised bogie of bogie.h written again here from its header's equations (the defaults of
    config/bogie_default.yaml, the carbody fixed): the 13 x 13 matrix at speed v [m/s] and conicity lam."""
    import numpy as np
    m, I, d0, d1, r0, f = 1869.0, 910.0, 0.7465, 1.0, 0.43, 7.99e6
    mf, jf, b, ka, da, cd, kd, dd = 2600.0, 1800.0, 1.25, 1.5e5, 1.0, 1e6, 5e7, 1.3
    kg = kx * (ratio - 1.0)
    n = 13
    # the equations as forces: M x'' = ... ; row by row, states y1 y1' p1 p1' y2 y2' p2 p2' yf yf' pf pf' u
    A = np.zeros((n, n))
    xs = (b, -b)
    for i in range(2):
        o = 4 * i
        A[o, o + 1] = 1.0
        A[o + 2, o + 3] = 1.0
        # m y'' = -2f/v y' + 2f psi - kg y - ky (y - yf - x psif)
        A[o + 1, [o, o + 1, o + 2, 8, 10]] = np.array([-kg - ky, -2 * f / v, 2 * f, ky, ky * xs[i]]) / m
        # I psi'' = -2 f d0 lam / r0 y - 2 f d0^2 / v psi' - kx d1^2 (psi - psif)
        A[o + 3, [o, o + 2, o + 3, 10]] = np.array([-2 * f * d0 * lam / r0, -kx * d1 ** 2, -2 * f * d0 ** 2 / v,
                                                    kx * d1 ** 2]) / I
    A[8, 9] = 1.0
    A[10, 11] = 1.0
    for i in range(2):
        o = 4 * i
        A[9, o] += ky / mf
        A[9, 8] -= ky / mf
        A[9, 10] -= ky * xs[i] / mf
        A[11, o] += xs[i] * ky / jf
        A[11, o + 2] += kx * d1 ** 2 / jf
        A[11, 8] -= xs[i] * ky / jf
        A[11, 10] -= (xs[i] ** 2 * ky + kx * d1 ** 2) / jf
    A[9, 8] -= ksy / mf
    A[9, 9] -= csy / mf
    A[11, 10] -= (2 * ka * da ** 2 + 2 * dd ** 2 * kd) / jf
    A[11, 12] += 2 * dd * kd / jf
    A[12, 10] = kd * dd / cd
    A[12, 12] = -kd / cd
    return A


def car_matrix(v, lam, ratio=1.351186, ksy=2.5e5, csy=3e4, mc=35000.0, ic=1.8e6, a=8.75, roll=None):
    """The linearised car of car.h from its header's equations: two bogies (bogie_matrix, their secondary acting on
    the frame's motion relative to the carbody at x_j = +-a, at h below its centre of mass) and the carbody
    (mc yc'' = sum F_j, Ic psic'' = sum x_j F_j + M_j, with roll = (Ix, h, kr, cr) also Ix phic'' = sum (h F_j - kr
    phic - cr phic') + mc g h phic); the 30 x 30 (32 x 32) matrix at speed v [m/s] and conicity lam
    (config/car_default.yaml's values by default)."""
    import numpy as np
    mf, jf, ka, da, cd, kd, dd = 2600.0, 1800.0, 1.5e5, 1.0, 1e6, 5e7, 1.3
    kyaw = 2 * ka * da ** 2 + 2 * dd ** 2 * kd  # the air springs' and yaw dampers' yaw stiffness on psif - psic
    n = 32 if roll else 30
    ix, h, kr, cr = roll if roll else (1.0, 0.0, 0.0, 0.0)
    A = np.zeros((n, n))
    Y, YD, P, PD = 26, 27, 28, 29
    A[Y, YD] = A[P, PD] = 1.0
    if roll:
        R, RD = 30, 31
        A[R, RD] = 1.0
        A[RD, R] = mc * 9.80665 * h / ix
    for j, x in enumerate((a, -a)):
        o = 13 * j
        A[o:o + 13, o:o + 13] = bogie_matrix(v, lam, ratio=ratio, ksy=ksy, csy=csy)
        yf, yfd, pf, u = o + 8, o + 9, o + 10, o + 12
        # the frame: its secondary forces on yf - yc - x psic - h phic and psif - psic
        A[yfd, [Y, YD, P, PD]] += np.array([ksy, csy, ksy * x, csy * x]) / mf
        A[o + 11, P] += kyaw / jf
        A[u, P] -= kd * dd / cd
        # the carbody: F_j = ksy (yf - yc - x psic - h phic) + csy (yf' - yc' - x psic' - h phic'),
        # M_j = 2 ka da^2 (psif - psic) + 2 dd kd (dd (psif - psic) - u)
        F = np.zeros(n)
        F[[yf, yfd, Y, YD, P, PD]] = [ksy, csy, -ksy, -csy, -ksy * x, -csy * x]
        M = np.zeros(n)
        M[[pf, P, u]] = [kyaw, -kyaw, -2 * dd * kd]
        if roll:
            F[[R, RD]] = [-ksy * h, -csy * h]
            A[yfd, [R, RD]] += np.array([ksy * h, csy * h]) / mf
            A[RD] += h * F / ix
            A[RD, [R, RD]] -= np.array([kr, cr]) / ix
        A[YD] += F / mc
        A[PD] += (x * F + M) / ic
    return A


def bisect_critical(matrix, v0_kmh=100.0, step_kmh=5.0):
    """The first speed [km/h] above v0 (up to 1500) where matrix(v [m/s])'s largest real part turns positive (steps,
    then 50 halvings), and the frequency [Hz] of that eigenvalue."""
    import numpy as np

    def abscissa(v_kmh):
        e = np.linalg.eigvals(matrix(v_kmh / 3.6))
        k = int(np.argmax(e.real))
        return e[k].real, abs(e[k].imag) / (2 * math.pi)

    lo, hi = v0_kmh, v0_kmh
    while abscissa(hi)[0] < 0:
        lo, hi = hi, hi + step_kmh
        assert hi <= 1500.0, "no critical speed in 100-1500 km/h"
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abscissa(mid)[0] < 0 else (lo, mid)
    return hi, abscissa(hi)[1]

def test_bogie_critical_and_eig():
    """`hunting critical` and `eig` on config/bogie_default.yaml against a second implementation (numpy's eigvals of
    bogie_matrix, bisected here), and the frame held against MODEL.md's 517.618 km/h."""
    import numpy as np
    cfg = os.path.join(SRC, "config", "bogie_default.yaml")
    for lam in (0.1358, 0.2, 0.3):
        out = run_json("critical", "--config", cfg, "--conicity", str(lam))
        assert out["model"] == "bogie", out
        v_ref, f_ref = bisect_critical(lambda v: bogie_matrix(v, lam))
        close(out["v_crit_kmh"], v_ref, 1e-4, f"bogie critical speed at {lam}")
        close(out["frequency_hz"], f_ref, 1e-4, f"bogie critical frequency at {lam}")
        shares = out["mode_energy_share"]
        close(shares["wheelsets"] + shares["bogie frame"], 1.0, 1e-12, "energy shares")
        assert out["mode"] == max(shares, key=shares.get), out
    close(run_json("critical", "--config", cfg)["frame_held_v_crit_kmh"], 517.618, 6e-4, "the frame held")
    eig = run_json("eig", "--config", cfg, "--v", "450")
    ref = sorted(np.linalg.eigvals(bogie_matrix(450 / 3.6, 0.1358)), key=lambda z: (-z.real, -z.imag))
    assert len(eig["eigenvalues"]) == 13 and eig["stable"] is True, eig
    for (re, im), z in zip(eig["eigenvalues"], ref):
        close(re, z.real, 1e-7 * abs(z), "bogie eigenvalue (real)")
        close(im, z.imag, 1e-7 * abs(z), "bogie eigenvalue (imaginary)")
    # a bogie config where a wheelset is expected, and a bad bogie: clear errors
    p = run("hopf", "--config", cfg, ok=False)
    assert p.returncode != 0 and "model: 'bogie' where a wheelset config is expected" in p.stderr, p.stderr
    with tempfile.TemporaryDirectory() as d:
        bad = write_file(d, "bad.yaml", open(cfg).read().replace("frame_mass_kg: 2600", "frame_mass_kg: -5"))
        p = run("critical", "--config", bad, ok=False)
        assert p.returncode != 0 and "bogie.frame_mass_kg: must be > 0 (got -5)" in p.stderr, p.stderr


def test_bogie_cycles():
    """`hunting cycles` on config/bogie_default.yaml: born at the bogie's critical speed (as `critical` says), the
    Floquet stability changing at each fold, CSV and JSON the same branch; options a bogie does not take refused."""
    cfg = os.path.join(SRC, "config", "bogie_default.yaml")
    crit = run_json("critical", "--config", cfg)
    out = run_json("cycles", "--config", cfg, "--v-min", "450", "--v-max", "700", "--amp-max", "0.0065")
    assert out["model"] == "bogie", out
    close(out["hopf"]["v_kmh"], crit["v_crit_kmh"], 1e-6, "the family's Hopf speed")
    close(out["branch"][0]["v_kmh"], crit["v_crit_kmh"], 0.05, "the first cycle at the Hopf speed")
    close(out["branch"][0]["frequency_hz"], crit["frequency_hz"], 0.01, "the first cycle's frequency")
    assert len(out["folds"]) >= 1, out["folds"]
    br = out["branch"]
    for f in out["folds"]:
        k = f["index"]  # between points k - 1 and k: the stability flips there
        assert br[k - 1]["stable"] != br[k]["stable"], (f, br[k - 1], br[k])
        pair = (br[k - 1]["v_kmh"], br[k]["v_kmh"])  # a fold is the branch's extreme speed between them
        assert f["v_kmh"] >= max(pair) - 1e-9 or f["v_kmh"] <= min(pair) + 1e-9, (f, pair)
    csv_rows = run("cycles", "--config", cfg, "--v-min", "450", "--v-max", "700", "--amp-max", "0.0065",
                   "--csv").stdout.strip().splitlines()
    assert len(csv_rows) == len(br) + 1, (len(csv_rows), len(br))
    close(float(csv_rows[-1].split(",")[1]), br[-1]["amplitude_m"], 1e-12, "the CSV's last amplitude")
    p = run("cycles", "--config", cfg, "--param", "kx", ok=False)
    assert p.returncode != 0 and "continued in speed only" in p.stderr, p.stderr


def test_car_critical_and_cycles():
    """The whole vehicle (config/car_default.yaml): with its carbody held its critical speed is the bogie's; the
    origin's stability flips within 0.01 km/h of its own (eig); its family starts there; its critical speed and that
    of config/car_carbody_hunting.yaml's carbody at conicity 0.01 and 0.02 against car_matrix's, bisected here."""
    car = os.path.join(SRC, "config", "car_default.yaml")
    bogie = os.path.join(SRC, "config", "bogie_default.yaml")
    out = run_json("critical", "--config", car)
    assert out["model"] == "car" and len(out["eigenvalues"]) == 30, out["model"]
    close(out["carbody_held_v_crit_kmh"], run_json("critical", "--config", bogie)["v_crit_kmh"], 1e-6,
          "the held carbody's critical speed against the bogie's")
    below = run_json("eig", "--config", car, "--v", str(out["v_crit_kmh"] - 0.01))
    above = run_json("eig", "--config", car, "--v", str(out["v_crit_kmh"] + 0.01))
    assert below["stable"] is True and above["stable"] is False, (below["least_damped"], above["least_damped"])
    fam = run_json("cycles", "--config", car, "--v-min", "450", "--v-max", "700", "--amp-max", "0.004")
    assert fam["model"] == "car", fam["model"]
    close(fam["hopf"]["v_kmh"], out["v_crit_kmh"], 1e-6, "the car family's Hopf speed")
    v_ref, f_ref = bisect_critical(lambda v: car_matrix(v, 0.1358))
    close(out["v_crit_kmh"], v_ref, 1e-4, "the car's critical speed against car_matrix")
    close(out["frequency_hz"], f_ref, 1e-4, "the car's critical frequency against car_matrix")
    # carbody hunting (config/car_carbody_hunting.yaml): at low conicity the carbody's mode goes first
    hunt = os.path.join(SRC, "config", "car_carbody_hunting.yaml")
    for lam in (0.01, 0.02):
        got = run_json("critical", "--config", hunt, "--conicity", str(lam))
        v_ref, f_ref = bisect_critical(lambda v: car_matrix(v, lam, ratio=1.0, ksy=4e5, csy=1e4, mc=30000.0,
                                                            ic=2.5e6))
        close(got["v_crit_kmh"], v_ref, 1e-4, f"carbody hunting's critical speed at {lam}")
        close(got["frequency_hz"], f_ref, 1e-4, f"carbody hunting's frequency at {lam}")
        assert got["mode"] == "carbody" and got["mode_energy_share"]["carbody"] > 0.9, got["mode_energy_share"]
    # the carbody's roll (config/car_roll.yaml): 32 states; its critical speed, and the rolling carbody-hunting car's
    # at conicity 0.01, against car_matrix's with roll
    roll = (6.4e4, 0.9, 2.6e6, 6.76e4)
    rolling = run_json("critical", "--config", os.path.join(SRC, "config", "car_roll.yaml"))
    assert len(rolling["eigenvalues"]) == 32, len(rolling["eigenvalues"])
    v_ref, f_ref = bisect_critical(lambda v: car_matrix(v, 0.1358, roll=roll))
    close(rolling["v_crit_kmh"], v_ref, 1e-4, "the rolling car's critical speed against car_matrix")
    close(rolling["frequency_hz"], f_ref, 1e-4, "the rolling car's critical frequency against car_matrix")
    roll_text = open(os.path.join(SRC, "config", "car_roll.yaml")).read()
    with tempfile.TemporaryDirectory() as d:
        cfg = write_file(d, "hunt_roll.yaml", open(hunt).read() + roll_text[roll_text.index("  roll:"):])
        got = run_json("critical", "--config", cfg, "--conicity", "0.01")
        v_ref, f_ref = bisect_critical(lambda v: car_matrix(v, 0.01, ratio=1.0, ksy=4e5, csy=1e4, mc=30000.0, ic=2.5e6,
                                                            roll=roll))
        close(got["v_crit_kmh"], v_ref, 1e-4, "the rolling carbody hunting's critical speed")
        close(got["frequency_hz"], f_ref, 1e-4, "the rolling carbody hunting's frequency")
        assert got["mode"] == "carbody", got["mode_energy_share"]


def test_bogie_and_car_simulate():
    """`hunting simulate` on a bogie and a car: a frame or carbody accelerometer's stream that `hunting estimate`
    reads; on a perfect track from a kick below the critical speed the leading wheelset's motion decays at the rate
    `hunting eig` gives (the least-damped mode's real part, fitted to the envelope); a place not on the model is
    refused."""
    bogie = os.path.join(SRC, "config", "bogie_default.yaml")
    car = os.path.join(SRC, "config", "car_default.yaml")
    with tempfile.TemporaryDirectory() as d:
        acc, spd, st = (os.path.join(d, n) for n in ("a.csv", "s.csv", "st.csv"))
        run("simulate", "--config", bogie, "--v", "450", "--t", "30", "--irregularity", "0.3", "--sensor", "frame",
            "--dt-out", "0.002", "--accel-noise", "0.05", "--accel-out", acc, "--speed-out", spd, "--out", st)
        lines = estimate_lines(acc, spd, 30)
        assert lines and lines[-1]["accel_samples"] == 15001, lines[-1]["accel_samples"]
        # 530 km/h, 11 km/h below the critical speed: the least-damped mode well apart from the others
        run("simulate", "--config", bogie, "--v", "530", "--t", "12", "--x0", "0.0001,0,0,0", "--dt-out", "0.001",
            "--out", st)
        rows = list(csv.DictReader(open(st)))
        eig = run_json("eig", "--config", bogie, "--v", "530")
        sigma = max(e[0] for e in eig["eigenvalues"] if e[1] > 1.0)  # the least-damped oscillatory mode
        # the envelope: max |y1| over 1 s blocks from 3 s on (the faster modes gone), its log-linear slope
        t_blocks, logs = [], []
        for k in range(3, 12):
            seg = [abs(float(r["y_m"])) for r in rows if k < float(r["t_s"]) <= k + 1]
            t_blocks.append(k + 0.5)
            logs.append(math.log(max(seg)))
        n = len(t_blocks)
        mt, ml = sum(t_blocks) / n, sum(logs) / n
        slope = sum((t - mt) * (l - ml) for t, l in zip(t_blocks, logs)) / sum((t - mt) ** 2 for t in t_blocks)
        close(slope, sigma, 0.03 * abs(sigma), "the kick's decay against the least-damped eigenvalue")
        p = run("simulate", "--config", car, "--v", "300", "--t", "1", "--sensor", "roof", ok=False)
        assert p.returncode != 0 and "'roof' is not a place on a car" in p.stderr, p.stderr


def test_sweep_on_a_bogie():
    """`hunting sweep --config bogie.yaml` (issue #28): at each conicity the bogie's critical speed is `hunting critical
    --config --conicity`'s (each row's conicity set on its own), and with the frame held it is the lone wheelset's
    closed form (the wheelset's sweep, a second method: Hurwitz against eigenvalue bisection) to 1e-6 km/h."""
    bogie = os.path.join(SRC, "config", "bogie_default.yaml")
    rows = run_json("sweep", "--config", bogie, "--from", "0.1", "--to", "0.3", "--n", "3")["rows"]
    wheelset = run_json("sweep", "--from", "0.1", "--to", "0.3", "--n", "3")["rows"]
    assert len(rows) == 3 and len(wheelset) == 3, (rows, wheelset)
    for r, w in zip(rows, wheelset):
        one = run_json("critical", "--config", bogie, "--conicity", repr(r["conicity"]))
        close(r["v_crit_kmh"], one["v_crit_kmh"], 1e-9, f"the bogie's critical speed at {r['conicity']}")
        close(r["frame_held_v_crit_kmh"], w["v_crit_kmh"], 1e-6, f"frame held = wheelset at {r['conicity']}")
    p = run("sweep", "--config", bogie, "--table", ok=False)
    assert p.returncode != 0 and "--table takes the wheelset" in p.stderr, p.stderr


def test_estimate_on_a_bogie_model():
    """`hunting estimate --config bogie.yaml`: the monitor on the bogie's model (issue #28). Its boundary table from
    `hunting tables --config`, refused by a wheelset monitor; before any window the Hopf interval is the prior's
    conicities (the configured 0.1358 -+ 0.03) through the bogie's own critical speeds (`hunting critical --config
    --conicity`, a separate path: eigenvalue bisection against the monitor's interpolated curve, to 0.05 km/h); a frame
    accelerometer's windows read as the bogie's conicity; its state file restored by its own monitor, refused by a
    wheelset's."""
    bogie = os.path.join(SRC, "config", "bogie_default.yaml")
    with tempfile.TemporaryDirectory() as d:
        tbl, acc, spd = (os.path.join(d, n) for n in ("b.tbl", "a.csv", "s.csv"))
        out = run_json("tables", "--config", bogie, "--out", tbl, "--n", "4", "--conicity-min", "0.10",
                       "--conicity-max", "0.19")
        assert out["conicities"] == 4, out
        run("simulate", "--config", bogie, "--profile", "0:470,80:470", "--t", "80", "--irregularity", "0.3",
            "--seed", "5", "--sensor", "frame", "--dt-out", "0.002", "--accel-noise", "0.1", "--accel-out", acc,
            "--speed-out", spd)
        mon = write_file(d, "mon.yaml", open(os.path.join(SRC, "config", "monitor.yaml")).read().replace(
            "measurement_point: wheelset", "measurement_point: bogie_frame"))
        rows = lines(run("estimate", "--config", bogie, "--table", tbl, "--monitor", mon, "--accel", acc, "--speed",
                         spd, "--every", "5").stdout)
        lo = run_json("critical", "--config", bogie, "--conicity", str(0.1358 + 0.03))["v_crit_kmh"]
        hi = run_json("critical", "--config", bogie, "--conicity", str(0.1358 - 0.03))["v_crit_kmh"]
        first = rows[0]
        assert first["conicity_estimate"] is None, first["conicity_estimate"]
        close(first["hopf_kmh_low"], lo, 0.05, "the prior's lower end by the bogie's model")
        close(first["hopf_kmh_high"], hi, 0.05, "the prior's upper end by the bogie's model")
        last = rows[-1]
        assert last["conicity_estimate"] is not None and abs(last["conicity_estimate"] - 0.1358) < 0.02, last
        p = run("estimate", "--table", tbl, "--accel", acc, "--speed", spd, ok=False)
        assert p.returncode != 0 and "not for this vehicle" in p.stderr, p.stderr
        # a state file of the bogie's monitor: restored by the same monitor (its first line's estimate the one the
        # writing run ended with, from the same windows), refused by a wheelset's
        st = os.path.join(d, "st")
        part = {n: os.path.join(d, n) for n in ("a1", "s1", "a2", "s2")}
        split_recording(acc, 60.0, part["a1"], part["a2"])
        split_recording(spd, 60.0, part["s1"], part["s2"])
        written = lines(run("estimate", "--config", bogie, "--table", tbl, "--monitor", mon, "--accel", part["a1"],
                            "--speed", part["s1"], "--every", "5", "--state-out", st).stdout)
        again = lines(run("estimate", "--config", bogie, "--table", tbl, "--monitor", mon, "--accel", part["a2"],
                          "--speed", part["s2"], "--every", "5", "--state-in", st).stdout)
        n_win = written[-1]["windows_used"]
        assert n_win > 0 and again[0]["restored"].startswith(f"restored, age 0 s, {n_win} window"), again[0]
        close(again[0]["conicity_estimate"], written[-1]["conicity_estimate"], 1e-9, "the restored estimate")
        p = run("estimate", "--accel", part["a2"], "--speed", part["s2"], "--every", "5", "--state-in", st,
                "--table", shipped_table())
        assert "not restored: " in p.stderr and "another vehicle" in p.stderr, p.stderr


def main():
    global failures
    tests = [(n, f) for n, f in globals().items() if n.startswith("test_") and callable(f)]
    for name, fn in tests:
        try:
            fn()
            print(f"PASS {name}")
        except Exception as e:  # noqa: BLE001 - report every failure and go on
            failures += 1
            print(f"  {type(e).__name__}: {e}")
            print(f"FAIL {name}")
        sys.stdout.flush()
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
