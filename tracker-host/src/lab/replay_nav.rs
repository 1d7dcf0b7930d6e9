//! `tracker-host replay --filter ttkf`: paper 004's dead-reckoning filter over recorded
//! own-ship sensors feeding a target-tracking filter over recorded radar fixes.
//!
//! - `--input` (polar): `t,range,bearing` (s, m, degrees true), t strictly increasing;
//! - `--nav`: `t` and any of `gps_x,gps_y,gps_vx,gps_vy,loran_x,loran_y,speedlog,gyro`
//!   (m, m/s, m, m/s, degrees true) in the output's east/north frame; an empty cell (or a
//!   missing column) means not available. Without any position sensor, own ship starts at
//!   (0, 0) at the first nav time;
//! - output: the replay contract's `t,x,y,vx,vy,px,py,ex,ey` for the target (the innovation is
//!   the fix's position minus the prediction), then `range,bearing,cpa,tcpa,course,speed,
//!   rel_course,rel_speed` (m, degrees true, m, s, degrees, m/s; over ground, and relative to
//!   own ship), one row per radar fix. Errors name the file and line; no partial output.

use std::path::Path;

use crate::csv_input;
use anyhow::{anyhow, bail, Context};
use tracker_core::nav::drkf::{Drkf, DrkfConfig, NavFix};
use tracker_core::nav::ttkf::{OwnShipEstimate, Ttkf, TtkfConfig};
use tracker_core::nav::GaussMarkov;

/// Radar options.
#[derive(Clone, Copy, Debug)]
pub struct RadarNoise {
    /// Range σ, m.
    pub range_sd_m: f64,
    /// Bearing σ, degrees.
    pub bearing_sd_deg: f64,
}

/// One radar fix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polar {
    /// Time, s.
    pub t: f64,
    /// Range, m.
    pub range_m: f64,
    /// Bearing, degrees true.
    pub bearing_deg: f64,
}

/// Rows of a CSV as optional numbers per named column (`names`, in that order); the file
/// may have only those columns (a misspelled one is an error naming it, not a sensor
/// silently missing), each once; `required` ones must be filled; t must increase. Errors
/// name the file, line and column.
fn read_columns(
    path: &Path,
    names: &[&str],
    required: &[&str],
) -> anyhow::Result<Vec<Vec<Option<f64>>>> {
    let optional: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| !required.contains(n))
        .collect();
    let (mut reader, header) = csv_input::open(path, required, &optional)?;
    let mut rows = Vec::new();
    let mut last_t = f64::NEG_INFINITY;
    let mut record = csv::StringRecord::new();
    while csv_input::read(&mut reader, &header, &mut record)? {
        let row_in = header.row(&record);
        let mut row = Vec::with_capacity(names.len());
        for c in names {
            let v = if required.contains(c) {
                Some(row_in.required_number(c)?)
            } else {
                row_in.number(c)?
            };
            row.push(v);
        }
        let t = row[0].unwrap_or(f64::NAN);
        if t <= last_t {
            return Err(row_in.error("t", &format!("{t} does not increase (previous {last_t})")));
        }
        last_t = t;
        rows.push(row);
    }
    if rows.is_empty() {
        bail!("{}: no rows", header.file());
    }
    Ok(rows)
}

const NAV: [&str; 9] = [
    "t", "gps_x", "gps_y", "gps_vx", "gps_vy", "loran_x", "loran_y", "speedlog", "gyro",
];

fn nav_fix(row: &[Option<f64>]) -> NavFix {
    let pair = |a: usize, b: usize| match (row[a], row[b]) {
        (Some(x), Some(y)) => Some([x, y]),
        _ => None,
    };
    NavFix {
        gps_position_m: pair(1, 2),
        gps_velocity_mps: pair(3, 4),
        loran_position_m: pair(5, 6),
        speedlog_mps: row[7],
        gyro_rad: row[8].map(f64::to_radians),
    }
}

/// One output row.
#[derive(Clone, Copy, Debug)]
pub struct NavRow {
    /// t,x,y,vx,vy,px,py,ex,ey,range,bearing,cpa,tcpa,course,speed,rel_course,rel_speed.
    pub values: [f64; 17],
}

/// The output header.
pub const HEADER: &str =
    "t,x,y,vx,vy,px,py,ex,ey,range,bearing,cpa,tcpa,course,speed,rel_course,rel_speed";

/// Runs the filters over the recorded data.
///
/// # Errors
/// A filter refusing a fix or an interval, naming its time.
pub fn run(
    polar: &[Polar],
    nav: &[Vec<Option<f64>>],
    noise: RadarNoise,
) -> anyhow::Result<Vec<NavRow>> {
    let err = |e: tracker_core::filter::FilterError| anyhow!("filter refused: {e}");
    // Errors at a row name its line (the header is line 1).
    let nav_err =
        |i: usize| move |e: tracker_core::filter::FilterError| anyhow!("nav line {}: {e}", i + 2);
    let input_err =
        |i: usize| move |e: tracker_core::filter::FilterError| anyhow!("input line {}: {e}", i + 2);
    let first = nav.first().ok_or_else(|| anyhow!("no own-ship data"))?;
    let fix0 = nav_fix(first);
    let pos0 = fix0
        .gps_position_m
        .or(fix0.loran_position_m)
        .unwrap_or([0.0, 0.0]);
    let vel0 = fix0
        .gps_velocity_mps
        .unwrap_or_else(|| match (fix0.speedlog_mps, fix0.gyro_rad) {
            (Some(s), Some(g)) => [s * g.sin(), s * g.cos()],
            _ => [0.0, 0.0],
        });
    let mut drkf = Drkf::<f64>::new(
        DrkfConfig::table_1(1).unwrap_or_else(|| unreachable!()),
        pos0,
        vel0,
        30.0,
        2.0,
    )
    .map_err(err)?;
    let t0 = first[0].unwrap_or(0.0);
    drkf.update(&fix0).map_err(err)?;
    let config = TtkfConfig {
        own_acceleration: GaussMarkov::with_variance(0.01 * 0.01, 0.05),
        target_acceleration: GaussMarkov::with_variance(0.01 * 0.01, 1.0 / 60.0),
        range_var_m2: noise.range_sd_m * noise.range_sd_m,
        bearing_var_rad2: noise.bearing_sd_deg.to_radians().powi(2),
        initial_speed_sd_mps: 10.0,
        glint_sd_m: 0.0,
    };
    let own = |d: &Drkf<f64>| OwnShipEstimate {
        position_m: d.position_m(),
        velocity_mps: d.velocity_over_ground_mps(),
        covariance: d.own_ship_covariance(),
    };
    let mut ttkf: Option<Ttkf<f64>> = None;
    let mut now = t0;
    let mut out = Vec::with_capacity(polar.len());
    let (mut ni, mut pi) = (1usize, 0usize);
    // Events in time order; at equal times own-ship data first.
    while pi < polar.len() {
        let next_nav = nav.get(ni).and_then(|r| r[0]);
        let p = polar[pi];
        let is_nav = next_nav.is_some_and(|t| t <= p.t);
        let t = if is_nav { next_nav.unwrap_or(p.t) } else { p.t };
        if t < now {
            bail!(
                "radar fix at t = {} precedes the first own-ship data (t = {t0})",
                p.t
            );
        }
        if t > now {
            let dt = t - now;
            drkf.predict(dt).map_err(err)?;
            if let Some(f) = ttkf.as_mut() {
                f.predict(dt).map_err(err)?;
            }
            now = t;
        }
        if is_nav {
            drkf.update(&nav_fix(&nav[ni])).map_err(nav_err(ni))?;
            if let Some(f) = ttkf.as_mut() {
                f.update_own_ship(&own(&drkf)).map_err(nav_err(ni))?;
            }
            ni += 1;
            continue;
        }
        let b = p.bearing_deg.to_radians();
        let (pred, fixpos) = match ttkf.as_mut() {
            None => {
                let f = Ttkf::new(config, &own(&drkf), p.range_m, b).map_err(input_err(pi))?;
                let tp = f.target_position_m();
                ttkf = Some(f);
                (tp, tp)
            }
            Some(f) => {
                let pred = f.target_position_m();
                let o = f.own_position_m();
                let fixpos = [o[0] + p.range_m * b.sin(), o[1] + p.range_m * b.cos()];
                f.update_radar(p.range_m, b).map_err(input_err(pi))?;
                (pred, fixpos)
            }
        };
        let f = ttkf.as_ref().ok_or_else(|| anyhow!("no track"))?;
        let (tp, tv, op, ov) = (
            f.target_position_m(),
            f.target_velocity_mps(),
            f.own_position_m(),
            f.own_velocity_mps(),
        );
        let rel = [tp[0] - op[0], tp[1] - op[1]];
        let rv = [tv[0] - ov[0], tv[1] - ov[1]];
        let (cpa, tcpa) = crate::lab::kinematics::cpa(rel, rv);
        let (course, speed) = crate::lab::kinematics::course_speed(tv);
        let (rel_course, rel_speed) = crate::lab::kinematics::course_speed(rv);
        out.push(NavRow {
            values: [
                p.t,
                tp[0],
                tp[1],
                tv[0],
                tv[1],
                pred[0],
                pred[1],
                fixpos[0] - pred[0],
                fixpos[1] - pred[1],
                rel[0].hypot(rel[1]),
                crate::lab::kinematics::course_speed(rel).0,
                cpa,
                tcpa,
                course,
                speed,
                rel_course,
                rel_speed,
            ],
        });
        pi += 1;
    }
    Ok(out)
}

/// Reads both files, runs, writes `output` atomically.
///
/// # Errors
/// A file that does not open or breaks its format (naming the line), a non-positive range, the filters' refusals, the output not written.
pub fn replay(input: &Path, nav: &Path, output: &Path, noise: RadarNoise) -> anyhow::Result<usize> {
    let polar: Vec<Polar> = read_columns(
        input,
        &["t", "range", "bearing"],
        &["t", "range", "bearing"],
    )?
    .into_iter()
    .map(|r| Polar {
        t: r[0].unwrap_or(f64::NAN),
        range_m: r[1].unwrap_or(f64::NAN),
        bearing_deg: r[2].unwrap_or(f64::NAN),
    })
    .collect();
    if let Some((i, p)) = polar.iter().enumerate().find(|(_, p)| p.range_m <= 0.0) {
        bail!(
            "{} line {}: range {} must be positive",
            input.display(),
            i + 2,
            p.range_m
        );
    }
    let navs = read_columns(nav, &NAV, &["t"])?;
    let rows = run(&polar, &navs, noise)?;
    let mut text = String::from(HEADER);
    text.push('\n');
    for r in &rows {
        let cells: Vec<String> = r.values.iter().map(|v| v.to_string()).collect();
        text += &cells.join(",");
        text.push('\n');
    }
    let tmp = output.with_extension("partial");
    std::fs::write(&tmp, text).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, output).with_context(|| format!("writing {}", output.display()))?;
    Ok(rows.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crossing_target_from_files() {
        let dir = std::env::temp_dir().join(format!("ttkf-replay-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Own ship north at 5 m/s from (0, 0), GPS for 60 s then gyro and log only;
        // target from (3000, 4000) west at 6 m/s.
        let mut nav = String::from("t,gps_x,gps_y,gps_vx,gps_vy,speedlog,gyro\n");
        for k in 0..=300 {
            let t = f64::from(k);
            if k < 60 {
                nav += &format!("{t},0,{},0,5,5,0\n", 5.0 * t);
            } else {
                nav += &format!("{t},,,,,5,0\n");
            }
        }
        let mut polar = String::from("t,range,bearing\n");
        for k in 0..120 {
            let t = 0.5 + 2.5 * f64::from(k);
            let (dx, dy) = (3000.0 - 6.0 * t, 4000.0 - 5.0 * t);
            polar += &format!(
                "{t},{},{}\n",
                dx.hypot(dy),
                dx.atan2(dy).to_degrees().rem_euclid(360.0)
            );
        }
        let (np, pp, out) = (
            dir.join("nav.csv"),
            dir.join("polar.csv"),
            dir.join("est.csv"),
        );
        std::fs::write(&np, nav).unwrap();
        std::fs::write(&pp, polar).unwrap();
        let noise = RadarNoise {
            range_sd_m: 20.0,
            bearing_sd_deg: 0.5,
        };
        assert_eq!(replay(&pp, &np, &out, noise).unwrap(), 120);
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(text.starts_with(HEADER));
        let last: Vec<f64> = text
            .lines()
            .last()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        // course 270°, speed 6; relative (−6, −5): 7.8 m/s.
        assert!((last[13] - 270.0).abs() < 2.0, "course {}", last[13]);
        assert!((last[14] - 6.0).abs() < 0.3, "speed {}", last[14]);
        assert!(
            (last[16] - 61f64.sqrt()).abs() < 0.3,
            "rel speed {}",
            last[16]
        );
        // Bad input: a line named, no output.
        std::fs::write(&pp, "t,range,bearing\n1,100,10\n1,100,10\n").unwrap();
        let _ = std::fs::remove_file(&out);
        let e = replay(&pp, &np, &out, noise).unwrap_err().to_string();
        assert!(e.contains("line 3"), "{e}");
        assert!(!out.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
