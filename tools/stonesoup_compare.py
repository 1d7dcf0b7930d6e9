#!/usr/bin/env python3
"""Compare our radar tracker with Stone Soup (Dstl) on the very same plots.

For each scenario and seed this script

1. runs our tracker (`tracker-host --link inproc demo ...`) twice, with
   `--association two-stage` and the rule `--second` names (`two-stage-unresolved`, the
   product's default since 2026-12-05, unless told `joint`),
   recording the plots, the truth,
   the tracks and the summary JSON into a work directory;
2. feeds the recorded plots (converted to the local east/north frame) scan by scan to a
   Stone Soup multi-target tracker set up with our models (CV Kalman, q = 0.05 m^2/s^3,
   R = 40^2 m^2, chi-square 99 % gate, GNN, 3-hit confirmation, see docs/stonesoup.md);
3. scores both trackers with the same code: OSPA and GOSPA (c = 500 m, p = 2, alpha = 2)
   between the truth targets in radar range (0.2 NM <= range <= 12 NM from own ship) and
   the confirmed + coasting tracks, untracked target-scans, track swaps (our scorer's rule),
   confirmed tracks; and checks
   that this OSPA/GOSPA of our tracks agrees with our tracker's own `ospa_per_scan_m`.

It prints a Markdown table (and writes it to `--markdown`, if given) and writes every
figure to `<workdir>/results-<deleter>.json`. It is a manual tool, not part of CI.

Set-up (outside CI; Python 3.10+):

    python3 -m venv /tmp/stonesoup-venv   # outside the work tree
    /tmp/stonesoup-venv/bin/pip install -r tools/stonesoup-requirements.txt
    cargo build --release -p tracker-host
    /tmp/stonesoup-venv/bin/python tools/stonesoup_compare.py \\
        --tracker target/release/tracker-host --workdir /tmp/stonesoup-compare \\
        --scenarios open-sea crossing --seeds 1 2 3 4 --markdown /tmp/stonesoup-table.md
"""

from __future__ import annotations

import argparse
import csv
import datetime as dt
import hashlib
import json
import math
import os
import subprocess
import sys
import time
from collections import defaultdict

try:
    import numpy as np
    from scipy.optimize import linear_sum_assignment
    import stonesoup  # noqa: F401  (checked here, used lazily)
except ImportError as e:
    sys.exit(f"{e}: run this with a Python that has tools/stonesoup-requirements.txt "
             "installed (see the set-up at the top of this file)")

NM_M = 1852.0
BLIND_RANGE_M = 0.2 * NM_M
MAX_RANGE_M = 12.0 * NM_M
OSPA_C_M = 500.0
OSPA_P = 2.0
FOLLOW_RADIUS_M = 300.0
SWAP_MARGIN_M = 100.0  # tracker-host/src/score/mod.rs MATCH_RADIUS_M, SWAP_MARGIN_M
SHOWN = ("confirmed", "coasting")

# Our models (tracker-host/src/session/mod.rs PLOT_SIGMA_M, tracker-core FilterConfig::tracking,
# tracker-host/src/session/associate.rs CHI2_2DOF_99, tracker-core/src/track.rs next_status).
PLOT_SIGMA_M = 40.0
Q_M2_S3 = 0.05
MAX_SPEED_MPS = 20.0
CHI2_2DOF_99 = 9.21
CONFIRM_HITS = 3
TENTATIVE_MAX_COASTS = 2
KEEP_M, KEEP_N = 5, 10  # the tracker's earlier rule: lost with fewer than 5 hits in its last 10 scans
CONFIRMED_MAX_COASTS = 6  # the tracker's rule now (LOST_AFTER_COASTS): 6 misses in a row


# ----------------------------------------------------------------------------------------
# Recorded files


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def load_truth(path):
    """Per scan (index in time order): list of (target, east, north, in_range); own ship
    (target 0) is taken out and used for the range. Also the scans' t_s strings."""
    by_t = defaultdict(list)
    for r in read_csv(path):
        by_t[r["t_s"]].append(r)
    out = {}
    for t, rows in by_t.items():
        own = next(r for r in rows if r["target"] == "0")
        oe, on = float(own["east_m"]), float(own["north_m"])
        targets = []
        for r in rows:
            if r["target"] == "0":
                continue
            e, n = float(r["east_m"]), float(r["north_m"])
            rng = math.hypot(e - oe, n - on)
            targets.append((int(r["target"]), e, n, BLIND_RANGE_M <= rng <= MAX_RANGE_M))
        out[t] = targets
    times = sorted(out, key=float)
    return [out[t] for t in times], times


def load_tracks(path):
    """Per scan: list of (track, east, north) of the confirmed and coasting tracks, and the
    set of every track id ever shown."""
    by_t = defaultdict(list)
    ever = set()
    for r in read_csv(path):
        if r["status"] in SHOWN:
            by_t[int(r["scan"])].append((int(r["track"]), float(r["east_m"]), float(r["north_m"])))
            ever.add(int(r["track"]))
    return by_t, ever


def on_link_grid(own_m, rng, brg):
    """The plot in the local frame as our tracker holds it: `geo::polar_to_local_f64` (own
    ship, range and bearing as the f32 the file prints, worked in f64, rounded to f32 once),
    then rounded to the link's 0.1 m grid (`tracker_core::icd::fixed`: tenths in f32,
    halves away from zero) and read back as f32 tenths."""
    f32 = np.float32
    r, b = float(f32(rng)), float(f32(brg))
    out = []
    for own, trig in ((own_m[0], math.sin), (own_m[1], math.cos)):
        x = f32(float(f32(own)) + r * trig(b))
        tenths = x * f32(10.0)
        steps = math.copysign(math.floor(abs(float(tenths)) + 0.5), float(tenths))
        out.append(float(f32(steps) / f32(10.0)))
    return out


def load_plots(path, unrounded=False):
    """Per scan: list of (east, north, range_m, bearing_rad): the plot in the local frame
    and as the radar measured it. The local position is the one our tracker associates
    (on the link's 0.1 m grid, computed in f32) unless `unrounded` (f64, as the first
    comparisons gave Stone Soup)."""
    by_t = defaultdict(list)
    for r in read_csv(path):
        rng, brg = float(r["range_m"]), math.radians(float(r["bearing_deg"]))
        own = (float(r["own_east_m"]), float(r["own_north_m"]))
        if unrounded:
            e = own[0] + rng * math.sin(brg)
            n = own[1] + rng * math.cos(brg)
        else:
            e, n = on_link_grid(own, rng, brg)
        by_t[int(r["scan"])].append((e, n, rng, brg))
    return by_t


def sha256_without_time(path):
    """The file's hash with its t_s column left out (a run's clock starts at the wall
    clock, so two runs differ there and nowhere else when they saw the same plots)."""
    h = hashlib.sha256()
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = next(rows)
        skip = header.index("t_s")
        for row in rows:
            h.update((",".join(c for i, c in enumerate(row) if i != skip) + "\n").encode())
    return h.hexdigest()


# ----------------------------------------------------------------------------------------
# Scoring (one implementation for every tracker)


def set_distance(truth, tracks, c=OSPA_C_M, p=OSPA_P):
    """OSPA and GOSPA (alpha = 2) between two lists of (east, north), as
    tracker-host/src/score/ospa.rs computes them: one optimal assignment of min(c, d)^p;
    pairs at c or beyond count as a missed target and a false track in GOSPA. Both empty:
    zero."""
    m, n = len(truth), len(tracks)
    big = max(m, n)
    if big == 0:
        return 0.0, 0.0
    cp = c**p
    sum_cut, loc, close = 0.0, 0.0, 0
    if m and n:
        a = np.asarray(truth, dtype=float)
        b = np.asarray(tracks, dtype=float)
        d = np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1])
        rows, cols = linear_sum_assignment(np.minimum(d, c) ** p)
        dd = d[rows, cols]
        sum_cut = float(np.sum(np.minimum(dd, c) ** p))
        near = dd < c
        loc = float(np.sum(dd[near] ** p))
        close = int(np.count_nonzero(near))
    ospa = ((sum_cut + cp * (big - min(m, n))) / big) ** (1.0 / p)
    gospa = (loc + cp / 2.0 * ((m - close) + (n - close))) ** (1.0 / p)
    return ospa, gospa


def follows(targets, tracks, radius=FOLLOW_RADIUS_M):
    """Targets followed this scan: each track follows the target it is optimally assigned
    to (minimum summed distance over all targets), if within `radius`."""
    if not targets or not tracks:
        return set()
    a = np.asarray([(e, n) for _, e, n, _ in targets], dtype=float)
    b = np.asarray([(e, n) for _, e, n in tracks], dtype=float)
    d = np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1])
    cost = np.where(d <= radius, d, 1e9)
    rows, cols = linear_sum_assignment(cost)
    return {targets[i][0] for i, j in zip(rows, cols) if d[i, j] <= radius}


def swaps_scan(targets, tracks, last):
    """Track swaps this scan, by our scorer's rule (tracker-host/src/score/mod.rs): a track
    stays with the target it followed while that one is within FOLLOW_RADIUS_M and no other
    is nearer by more than SWAP_MARGIN_M, else it follows the nearest within the radius; a
    change of target is a swap. `last` (track -> target) is updated."""
    n = 0
    pos = {tid: (e, n_) for tid, e, n_, _ in targets}
    for track, e, n_ in tracks:
        near = [(math.hypot(e - te, n_ - tn), tid) for tid, (te, tn) in pos.items()]
        near = [x for x in near if x[0] <= FOLLOW_RADIUS_M]
        if not near:
            continue
        d_near, nearest = min(near)
        prev = last.get(track)
        if prev in pos:
            d_prev = math.hypot(e - pos[prev][0], n_ - pos[prev][1])
            if d_prev <= FOLLOW_RADIUS_M and d_prev <= d_near + SWAP_MARGIN_M:
                continue
        if prev is not None and prev != nearest:
            n += 1
        last[track] = nearest
    return n


def score(truth, tracks_by_scan):
    """Per-scan OSPA/GOSPA, the untracked target-scans and the track swaps of one
    tracker's shown tracks."""
    ospa, gospa = [], []
    ever_followed = set()
    untracked = 0
    swaps, last = 0, {}
    for scan, targets in enumerate(truth):
        tracks = tracks_by_scan.get(scan, [])
        swaps += swaps_scan(targets, tracks, last)
        xs = [(e, n) for _, e, n, r in targets if r]
        ys = [(e, n) for _, e, n in tracks]
        o, g = set_distance(xs, ys)
        ospa.append(o)
        gospa.append(g)
        fol = follows(targets, tracks)
        for tid, _, _, in_range in targets:
            if not in_range:
                continue
            if tid in fol:
                ever_followed.add(tid)
            elif tid in ever_followed:
                untracked += 1
    return {
        "ospa_mean_m": float(np.mean(ospa)),
        "gospa_mean_m": float(np.mean(gospa)),
        "ospa_per_scan_m": ospa,
        "gospa_per_scan_m": gospa,
        "untracked_target_scans": untracked,
        "track_swaps": swaps,
    }


# ----------------------------------------------------------------------------------------
# Our tracker


def run_ours(tracker, scenario, seed, association, out_dir, reuse=False):
    os.makedirs(out_dir, exist_ok=True)
    paths = {k: os.path.join(out_dir, f"{k}.{'json' if k == 'summary' else 'csv'}")
             for k in ("plots", "truth", "tracks", "summary")}
    if reuse and os.path.exists(paths["summary"]):
        with open(paths["summary"]) as f:
            paths["summary_data"] = json.load(f)
        with open(os.path.join(out_dir, "time_s")) as f:
            paths["time_s"] = float(f.read())
        return paths
    cmd = [tracker, "--link", "inproc", "demo", "--scenario", scenario, "--seed", str(seed),
           "--association", association,
           "--record-plots", paths["plots"], "--record-truth", paths["truth"],
           "--record-tracks", paths["tracks"], "--summary-json", paths["summary"]]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    elapsed = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{proc.stderr}")
    with open(os.path.join(out_dir, "time_s"), "w") as f:
        f.write(f"{elapsed}\n")
    with open(paths["summary"]) as f:
        paths["summary_data"] = json.load(f)
    paths["time_s"] = elapsed
    return paths


# ----------------------------------------------------------------------------------------
# Stone Soup


def keep_m_of_n_deleter(m, n):
    """Our KEEP rule as a Stone Soup deleter: a track goes when it missed more than n - m of
    its last min(age, n) scans (one state per scan; the plot that started it is a hit)."""
    from stonesoup.base import Property
    from stonesoup.deleter.base import Deleter
    from stonesoup.types.update import Update

    class KeepMofNDeleter(Deleter):
        hits_m: int = Property(doc="hits needed ...")
        window_n: int = Property(doc="... in the last this many scans")

        def check_for_deletion(self, track, **kwargs):
            last = track.states[-self.window_n:]
            hits = sum(1 for st in last if isinstance(st, Update) and st.hypothesis)
            return len(last) - hits > self.window_n - self.hits_m

    return KeepMofNDeleter(hits_m=m, window_n=n)


def stonesoup_tracker(scans, measure_name, deleter_name, q=Q_M2_S3):
    """A Stone Soup MultiTargetTracker with our models (process noise `q`, m^2/s^3);
    `scans` is a list of (datetime, set of Detection), each with its measurement model."""
    from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
    from stonesoup.deleter.time import UpdateTimeStepsDeleter
    from stonesoup.hypothesiser.distance import DistanceHypothesiser
    from stonesoup.initiator.simple import MultiMeasurementInitiator
    from stonesoup.measures import Mahalanobis, SquaredMahalanobis
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.tracker.simple import MultiTargetTracker
    from stonesoup.types.state import GaussianState
    from stonesoup.updater.kalman import KalmanUpdater

    transition = _transition_model(q)
    measurement = _measurement_model()
    predictor = KalmanPredictor(transition)
    updater = KalmanUpdater(measurement)
    if measure_name == "squared-mahalanobis":
        # Gate d^2 < 9.21 and GNN on summed d^2 (ours: summed d^2 + ln|S|).
        measure, missed = SquaredMahalanobis(), CHI2_2DOF_99
    else:
        # Mahalanobis() is d, not d^2: the same gate is d < sqrt(9.21).
        measure, missed = Mahalanobis(), math.sqrt(CHI2_2DOF_99)
    hypothesiser = DistanceHypothesiser(predictor, updater, measure, missed_distance=missed)
    associator = GNNWith2DAssignment(hypothesiser)
    prior = GaussianState(
        np.zeros((4, 1)),
        np.diag([PLOT_SIGMA_M**2, MAX_SPEED_MPS**2, PLOT_SIGMA_M**2, MAX_SPEED_MPS**2]))
    initiator = MultiMeasurementInitiator(
        prior_state=prior,
        measurement_model=measurement,
        deleter=UpdateTimeStepsDeleter(TENTATIVE_MAX_COASTS),
        data_associator=GNNWith2DAssignment(
            DistanceHypothesiser(predictor, updater, measure, missed_distance=missed)),
        updater=updater,
        min_points=CONFIRM_HITS)
    if deleter_name == "update-time-steps":
        deleter = UpdateTimeStepsDeleter(CONFIRMED_MAX_COASTS)
    else:
        deleter = keep_m_of_n_deleter(KEEP_M, KEEP_N)
    return MultiTargetTracker(
        initiator=initiator,
        deleter=deleter,
        detector=scans,
        data_associator=associator,
        updater=updater)


def _transition_model(q):
    from stonesoup.models.transition.linear import (
        CombinedLinearGaussianTransitionModel, ConstantVelocity)
    return CombinedLinearGaussianTransitionModel([ConstantVelocity(q), ConstantVelocity(q)])


_MEAS = None


def _measurement_model():
    global _MEAS
    if _MEAS is None:
        from stonesoup.models.measurement.linear import LinearGaussian
        _MEAS = LinearGaussian(ndim_state=4, mapping=(0, 2),
                               noise_covar=np.diag([PLOT_SIGMA_M**2, PLOT_SIGMA_M**2]))
    return _MEAS


# The simulator's radar accuracy (tracker-core/src/sim.rs SensorModel::imo, range_sigma_m and
# bearing_sigma_rad): range errors 20 and 30 m with a uniform 0.01 NM quantisation; bearing
# 0.05 and 0.03 deg with uniform +-0.05 and +-0.1 deg.
RANGE_SIGMA_M = math.sqrt(20.0**2 + 30.0**2 + (0.01 * NM_M)**2 / 3.0)
BEARING_SIGMA_RAD = math.radians(math.sqrt(0.05**2 + 0.03**2 + (0.05**2 + 0.1**2) / 3.0))


def polar_model(range_m, bearing_rad):
    """The plot's own accuracy in the local frame (`--polar`): the range sigma along the
    line of sight, range x bearing sigma across it (a converted measurement; Lerro &
    Bar-Shalom 1993 without the debiasing, negligible at these bearing errors)."""
    from stonesoup.models.measurement.linear import LinearGaussian
    s, c = math.sin(bearing_rad), math.cos(bearing_rad)
    vr, vc = RANGE_SIGMA_M**2, (range_m * BEARING_SIGMA_RAD)**2
    cov = np.array([[vr * s * s + vc * c * c, (vr - vc) * s * c],
                    [(vr - vc) * s * c, vr * c * c + vc * s * s]])
    return LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=cov)


def epoch(t_s):
    return dt.datetime(1970, 1, 1) + dt.timedelta(seconds=float(t_s))


def run_stonesoup(times, plots_by_scan, tracks_csv, measure_name, deleter_name, polar=False,
                  q=Q_M2_S3):
    from stonesoup.types.detection import Detection

    model = _measurement_model()
    scans = []
    for scan, t in enumerate(times):
        ts = epoch(t)
        scans.append((ts, {Detection(np.array([[e], [n]]), timestamp=ts,
                                     measurement_model=polar_model(r, b) if polar else model)
                           for e, n, r, b in plots_by_scan.get(scan, [])}))
    tracker = stonesoup_tracker(scans, measure_name, deleter_name, q)
    ids = {}
    tracks_by_t = {}
    t0 = time.perf_counter()
    with open(tracks_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scan", "t_s", "track", "status", "east_m", "north_m", "vx_mps", "vy_mps"])
        for scan, (t, (_, tracks)) in enumerate(zip(times, tracker)):
            rows = []
            for trk in tracks:
                tid = ids.setdefault(trk.id, len(ids) + 1)
                x = np.asarray(trk.state_vector, dtype=float).ravel()
                rows.append((tid, x[0], x[2]))
                w.writerow([scan, t, tid, "confirmed", f"{x[0]:.3f}", f"{x[2]:.3f}",
                            f"{x[1]:.4f}", f"{x[3]:.4f}"])
            tracks_by_t[scan] = rows
    elapsed = time.perf_counter() - t0
    return tracks_by_t, len(ids), elapsed


# ----------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tracker", required=True, help="our tracker-host binary")
    ap.add_argument("--workdir", default="/tmp/stonesoup-compare")
    ap.add_argument("--scenarios", nargs="+", default=["open-sea", "crossing"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3, 4])
    ap.add_argument("--measure", choices=["squared-mahalanobis", "mahalanobis"],
                    default="squared-mahalanobis",
                    help="Stone Soup's gating/assignment distance (same gate either way)")
    ap.add_argument("--deleter", choices=["update-time-steps", "keep-m-of-n"],
                    default="update-time-steps",
                    help="Stone Soup's deleter of confirmed tracks: UpdateTimeStepsDeleter(6) "
                    "(six misses in a row, our rule), or our earlier 5-of-10 rule as a custom Deleter")
    ap.add_argument("--reuse", action="store_true",
                    help="reuse our runs already recorded in --workdir (Stone Soup only)")
    ap.add_argument("--markdown", help="also write the results table here")
    ap.add_argument("--second", choices=["joint", "two-stage-unresolved"],
                    default="two-stage-unresolved",
                    help="our second association rule, run beside two-stage (its column)")
    ap.add_argument("--polar", action="store_true",
                    help="give Stone Soup each plot's own polar accuracy (the simulator's range "
                         "and bearing sigmas) in place of our 40 m a side: an experiment, not "
                         "our models (docs/tracking.md)")
    ap.add_argument("--unrounded", action="store_true",
                    help="give Stone Soup the plots in f64 off the link's 0.1 m grid, as the "
                         "comparisons before 2026-12-07's evening did (ours see them on it)")
    ap.add_argument("--q", type=float, default=Q_M2_S3,
                    help="Stone Soup's process noise, m^2/s^3 (ours: 0.05)")
    args = ap.parse_args()

    import stonesoup
    second = args.second
    # An experiment's files beside the comparison's, not over them.
    variant = args.deleter + ("-polar" if args.polar else "") + \
        ("-unrounded" if args.unrounded else "") + \
        (f"-q{args.q:g}" if args.q != Q_M2_S3 else "")
    results = {"stonesoup_version": stonesoup.__version__, "measure": args.measure,
               "deleter": args.deleter, "second": second, "polar": args.polar,
               "unrounded": args.unrounded, "q": args.q,
               "tracker": os.path.abspath(args.tracker), "runs": []}
    for scenario in args.scenarios:
        for seed in args.seeds:
            base = os.path.join(args.workdir, f"{scenario}-{seed}")
            run = {"scenario": scenario, "seed": seed}
            ours = {a: run_ours(args.tracker, scenario, seed, a, os.path.join(base, a),
                                args.reuse)
                    for a in ("two-stage", second)}
            ref = ours["two-stage"]
            same = all(sha256_without_time(ours[second][k]) == sha256_without_time(ref[k])
                       for k in ("plots", "truth"))
            run["same_plots_and_truth"] = same
            truth, times = load_truth(ref["truth"])
            for a, o in ours.items():
                truth_a, _ = load_truth(o["truth"])
                by_scan, ever = load_tracks(o["tracks"])
                s = score(truth_a, by_scan)
                js = o["summary_data"]
                d_ospa = np.abs(np.asarray(s["ospa_per_scan_m"]) -
                                np.asarray(js["ospa_per_scan_m"]))
                d_gospa = np.abs(np.asarray(s["gospa_per_scan_m"]) -
                                 np.asarray(js["gospa_per_scan_m"]))
                run[a] = {
                    "ospa_mean_m": s["ospa_mean_m"], "gospa_mean_m": s["gospa_mean_m"],
                    "untracked_target_scans": s["untracked_target_scans"],
                    "track_swaps": s["track_swaps"],
                    "confirmed_tracks": len(ever), "time_s": o["time_s"],
                    "own": {k: js[k] for k in ("ospa_mean_m", "gospa_mean_m",
                                               "untracked_target_scans", "confirmed_tracks",
                                               "track_breaks", "track_swaps", "false_tracks",
                                               "rms_position_m")},
                    "ospa_max_abs_diff_per_scan_m": float(d_ospa.max()),
                    "gospa_max_abs_diff_per_scan_m": float(d_gospa.max()),
                    "scans": len(times), "own_scans": len(js["ospa_per_scan_m"]),
                }
            plots = load_plots(ref["plots"], args.unrounded)
            ss_by_t, ss_n, ss_time = run_stonesoup(
                times, plots, os.path.join(base, f"stonesoup-{variant}-tracks.csv"),
                args.measure, args.deleter, args.polar, args.q)
            s = score(truth, ss_by_t)
            # Our tracks come back over the link on its 0.1 m grid; Stone Soup's put on the
            # same grid tell what of a millimetre's difference that grid is.
            on_grid = {k: [(t, round(e, 1), round(n, 1)) for t, e, n in v]
                       for k, v in ss_by_t.items()}
            run["stonesoup_on_report_grid_ospa_mean_m"] = score(truth, on_grid)["ospa_mean_m"]
            run["stonesoup"] = {"ospa_mean_m": s["ospa_mean_m"],
                                "gospa_mean_m": s["gospa_mean_m"],
                                "untracked_target_scans": s["untracked_target_scans"],
                                "track_swaps": s["track_swaps"],
                                "confirmed_tracks": ss_n, "time_s": ss_time}
            results["runs"].append(run)
            print(f"{scenario} seed {seed}: OSPA {run['two-stage']['ospa_mean_m']:.1f} / "
                  f"{run[second]['ospa_mean_m']:.1f} / {run['stonesoup']['ospa_mean_m']:.1f} m, "
                  f"Stone Soup {ss_time:.1f} s", file=sys.stderr, flush=True)
    os.makedirs(args.workdir, exist_ok=True)
    with open(os.path.join(args.workdir, f"results-{variant}.json"), "w") as f:
        json.dump(results, f, indent=1)
    table = markdown(results)
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(table)


def markdown(results):
    second = results.get("second", "joint")
    names = ("two-stage", second, "stonesoup")
    lines = [
        f"Stone Soup {results['stonesoup_version']}, measure {results['measure']}, "
        f"deleter {results['deleter']}"
        + (", each plot's polar accuracy" if results.get("polar") else "")
        + (f", q {results['q']} m^2/s^3" if results.get("q", Q_M2_S3) != Q_M2_S3 else "")
        + ". "
        f"Each cell: ours two-stage / ours {second} / Stone Soup.",
        "",
        "| scenario | seed | OSPA mean, m | GOSPA mean, m | untracked target-scans "
        "| track swaps | confirmed tracks | time per run, s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    tot = defaultdict(list)

    def cell(run, key, fmt):
        return " / ".join(fmt.format(run[a][key]) for a in names)

    keys = (("ospa_mean_m", "{:.1f}"), ("gospa_mean_m", "{:.1f}"),
            ("untracked_target_scans", "{:d}"), ("track_swaps", "{:d}"),
            ("confirmed_tracks", "{:d}"),
            ("time_s", "{:.2f}"))
    for run in results["runs"]:
        lines.append(f"| {run['scenario']} | {run['seed']} | " +
                     " | ".join(cell(run, k, f) for k, f in keys) + " |")
        for a in names:
            for k, _ in keys:
                tot[(run["scenario"], a, k)].append(run[a][k])
    for scenario in dict.fromkeys(r["scenario"] for r in results["runs"]):
        cells = []
        for k, f in keys:
            f = "{:.1f}" if f == "{:d}" else f
            cells.append(" / ".join(f.format(float(np.mean(tot[(scenario, a, k)])))
                                    for a in names))
        lines.append(f"| **{scenario}** | mean | " + " | ".join(cells) + " |")
    lines += [
        "",
        f"OSPA mean to a tenth of a millimetre, m: ours two-stage / ours {second} / Stone Soup / "
        "Stone Soup's tracks on our tracks' 0.1 m report grid:",
        "",
        "| scenario | seed | OSPA mean, m |",
        "|---|---|---|",
    ]
    for run in results["runs"]:
        if "stonesoup_on_report_grid_ospa_mean_m" in run:
            lines.append(
                f"| {run['scenario']} | {run['seed']} "
                f"| {run['two-stage']['ospa_mean_m']:.4f} / {run[second]['ospa_mean_m']:.4f} / "
                f"{run['stonesoup']['ospa_mean_m']:.4f} / "
                f"{run['stonesoup_on_report_grid_ospa_mean_m']:.4f} |")
    lines += [
        "",
        "Cross-check against our tracker's own scores (its summary JSON):",
        "",
        "| scenario | seed | association | OSPA here / own, m | GOSPA here / own, m "
        "| max per-scan OSPA diff, m | max per-scan GOSPA diff, m | untracked here / own "
        "| swaps here / own | plots & truth same for both rules |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for run in results["runs"]:
        for a in ("two-stage", second):
            r = run[a]
            lines.append(
                f"| {run['scenario']} | {run['seed']} | {a} "
                f"| {r['ospa_mean_m']:.3f} / {r['own']['ospa_mean_m']:.3f} "
                f"| {r['gospa_mean_m']:.3f} / {r['own']['gospa_mean_m']:.3f} "
                f"| {r['ospa_max_abs_diff_per_scan_m']:.2g} "
                f"| {r['gospa_max_abs_diff_per_scan_m']:.2g} "
                f"| {r['untracked_target_scans']} / {r['own']['untracked_target_scans']} "
                f"| {r['track_swaps']} / {r['own']['track_swaps']} "
                f"| {'yes' if run['same_plots_and_truth'] else 'no'} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
