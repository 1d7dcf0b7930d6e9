//! Instruction counts of paper 004's navigation filters (the dead-reckoning EKF, the
//! per-target tracking EKFs and the coupled filter they replace), under
//! `qemu-system-arm -icount shift=0`, with the structured arithmetic the filters use beside
//! the plain dense reference.
//!
//! A binary of its own: without the device's 39 KB track table beside it the stack has room
//! for the dense reference's N×N temporaries and for the coupled filter. Same CSV as `bench`
//! (`tracker-host bench-mcu` runs both).
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use semihosting::println;
use tracker_core::nav::coupled::Coupled;
use tracker_core::nav::drkf::{Drkf, DrkfConfig, NavFix};
use tracker_core::nav::ttkf::{OwnShipEstimate, Ttkf, TtkfConfig};
use tracker_core::nav::{Algebra, Dense, GaussMarkov, Structured};
use tracker_firmware::icount::report as row;
use tracker_firmware::{board, icount};

/// The dead-reckoning and target-tracking EKFs of paper 004 in f32, with `A`'s covariance
/// arithmetic (the filters' structured one, or the plain dense reference): one DRKF second
/// (predict, gyro and log), the Van Loan discretisation it caches, and the TTKF's two updates.
/// RAM is the filter's own size.
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn nav_rows<A: Algebra>(counter: &mut icount::InstructionCounter) {
    let Some(mut drkf) = drkf::<A>() else {
        return;
    };
    let fix = dead_reckoning_fix();
    let per = icount::per_call(counter, 50, || {
        let d = black_box(&mut drkf);
        let _ = d.predict(1.0);
        let _ = d.update(black_box(&fix));
    });
    row(
        "drkf-second-gyro-log",
        A::NAME,
        per,
        core::mem::size_of::<Drkf<f32, A>>(),
    );
    let per = icount::per_call(counter, 50, || {
        let _ = black_box(&mut drkf).predict(black_box(1.0));
    });
    row("drkf-predict", A::NAME, per, 0);
    let per = icount::per_call(counter, 20, || {
        black_box(black_box(&drkf).transition(black_box(1.0)));
    });
    row("drkf-van-loan", A::NAME, per, 0);
    let own = handoff(&drkf);
    let Ok(mut ttkf) = Ttkf::<f32, A>::with_algebra(ttkf_config(), &own, 5000.0, 0.7) else {
        return;
    };
    let per = icount::per_call(counter, 50, || {
        let t = black_box(&mut ttkf);
        let _ = t.predict(1.0);
        let _ = t.update_own_ship(black_box(&own));
    });
    row(
        "ttkf-second-own-ship",
        A::NAME,
        per,
        core::mem::size_of::<Ttkf<f32, A>>(),
    );
    let per = icount::per_call(counter, 50, || {
        let _ = black_box(&mut ttkf).predict(black_box(1.0));
    });
    row("ttkf-predict", A::NAME, per, 0);
    let per = icount::per_call(counter, 50, || {
        let _ = black_box(&mut ttkf).update_radar(black_box(5000.0), black_box(0.7));
    });
    row("ttkf-radar", A::NAME, per, 0);
}

/// One second of the whole own-ship-plus-targets filter for `M` targets, two ways: the
/// DRTTKF (one DRKF, `M` TTKFs fed its estimate) and the coupled filter of `N` = 11 + 6`M`
/// states, both given the speedlog, the gyro and a radar plot of every target. The paper's
/// eq. 10 predicts the ratio from the state counts; this measures it. RAM is the filters'.
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn coupling_rows<A: Algebra, const N: usize, const M: usize>(
    counter: &mut icount::InstructionCounter,
) {
    let Some(mut drkf) = drkf::<A>() else {
        return;
    };
    let fix = dead_reckoning_fix();
    let plots: [(f32, f32); M] =
        core::array::from_fn(|t| (3000.0 + 500.0 * t as f32, 0.3 * t as f32));
    let own = handoff::<A>;
    let mut tracks: [Option<Ttkf<f32, A>>; M] = core::array::from_fn(|t| {
        let (r, b) = plots[t];
        Ttkf::with_algebra(ttkf_config(), &own(&drkf), f64::from(r), f64::from(b)).ok()
    });
    let per = icount::per_call(counter, 10, || {
        let d = black_box(&mut drkf);
        let _ = d.predict(1.0);
        let _ = d.update(black_box(&fix));
        let handoff = own(d);
        for (track, &(r, b)) in black_box(&mut tracks).iter_mut().flatten().zip(&plots) {
            let _ = track.predict(1.0);
            let _ = track.update_own_ship(&handoff);
            let _ = track.update_radar(f64::from(r), f64::from(b));
        }
    });
    let ram = core::mem::size_of::<Drkf<f32, A>>() + M * core::mem::size_of::<Ttkf<f32, A>>();
    println!("drttkf-second-{}-targets,{},{:.1},{}", M, A::NAME, per, ram);
    coupled_row::<A, N, M>(counter, &drkf, &fix, &plots);
}

/// The coupled half of [`coupling_rows`], in its own frame.
#[inline(never)]
fn coupled_row<A: Algebra, const N: usize, const M: usize>(
    counter: &mut icount::InstructionCounter,
    drkf: &Drkf<f32, A>,
    fix: &NavFix,
    plots: &[(f32, f32); M],
) {
    let plots64 = plots.map(|(r, b)| (f64::from(r), f64::from(b)));
    let Ok(mut coupled) = Coupled::<f32, N, A>::new(drkf, ttkf_config(), &plots64) else {
        return;
    };
    let per = icount::per_call(counter, 10, || {
        let c = black_box(&mut coupled);
        let _ = c.predict(1.0);
        let _ = c.update_nav(black_box(fix));
        for (t, &(r, b)) in plots.iter().enumerate() {
            let _ = c.update_radar(t, f64::from(r), f64::from(b));
        }
    });
    let ram = core::mem::size_of::<Coupled<f32, N, A>>();
    println!(
        "coupled-second-{}-targets,{},{:.1},{}",
        M,
        A::NAME,
        per,
        ram
    );
}

/// A DRKF of Table I test 1, at 5 m/s north-east.
fn drkf<A: Algebra>() -> Option<Drkf<f32, A>> {
    let config = DrkfConfig::table_1(1)?;
    Drkf::with_algebra(config, [0.0, 0.0], [5.0, 5.0], 10.0, 1.0).ok()
}

/// One second of dead reckoning: the log and the gyro, no position fix.
fn dead_reckoning_fix() -> NavFix {
    NavFix {
        speedlog_mps: Some(7.07),
        gyro_rad: Some(0.785),
        ..NavFix::default()
    }
}

/// The DRKF's estimate as a TTKF's own-ship measurement (eq. 9a).
fn handoff<A: Algebra>(d: &Drkf<f32, A>) -> OwnShipEstimate<f32> {
    OwnShipEstimate {
        position_m: d.position_m(),
        velocity_mps: d.velocity_over_ground_mps(),
        covariance: d.own_ship_covariance(),
    }
}

/// The TTKF of the ARPA scenarios (IMO sensor model).
fn ttkf_config() -> TtkfConfig {
    TtkfConfig {
        own_acceleration: GaussMarkov::with_variance(1e-8, 0.05),
        target_acceleration: GaussMarkov::with_variance(2.5e-7, 1.0 / 120.0),
        range_var_m2: 900.0,
        bearing_var_rad2: 1.3e-5,
        initial_speed_sd_mps: 10.0,
        glint_sd_m: 0.0,
    }
}

#[entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        board::exit(1)
    };
    let mut counter = icount::InstructionCounter::new(peripherals.SYST);
    println!("{}", icount::HEADER);
    nav_rows::<Structured>(&mut counter);
    nav_rows::<Dense>(&mut counter);
    coupling_rows::<Structured, 17, 1>(&mut counter);
    coupling_rows::<Structured, 23, 2>(&mut counter);
    coupling_rows::<Structured, 35, 4>(&mut counter);
    coupling_rows::<Dense, 17, 1>(&mut counter);
    coupling_rows::<Dense, 23, 2>(&mut counter);
    coupling_rows::<Dense, 35, 4>(&mut counter);
    board::exit(0)
}
