//! `tracker-host bench-mcu`: instruction counts on the emulated Cortex-M4F.
//!
//! Runs the firmware's `bench` binary under `qemu-system-arm -icount shift=0` (one
//! instruction per nanosecond of virtual time, read through SysTick: deterministic, the same
//! every run) and relays its CSV table.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context};

use crate::link::qemu;

/// The header every bench table starts with.
pub const HEADER: &str = "name,scalar,instructions_per_call,ram_bytes";

/// One row of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    /// What was measured.
    pub name: String,
    /// `f32`, `fixed`, or `-` where no scalar applies.
    pub scalar: String,
    /// Instructions per call, the call included, loop overhead subtracted.
    pub instructions_per_call: f64,
    /// Bytes of RAM the measured object occupies.
    pub ram_bytes: usize,
}

/// Parses the bench binary's output: the header, then rows; other lines are ignored.
///
/// # Errors
/// No header in `output`, no row after it, or a row whose count or size is not a number.
pub fn parse(output: &str) -> anyhow::Result<Vec<BenchRow>> {
    let mut lines = output.lines().skip_while(|l| l.trim() != HEADER);
    if lines.next().is_none() {
        bail!("no bench table in the output:\n{output}");
    }
    let mut rows = Vec::new();
    for line in lines {
        let f: Vec<&str> = line.trim().split(',').collect();
        let [name, scalar, instr, ram] = f[..] else {
            continue;
        };
        rows.push(BenchRow {
            name: name.to_string(),
            scalar: scalar.to_string(),
            instructions_per_call: instr
                .parse()
                .with_context(|| format!("bad count in `{line}`"))?,
            ram_bytes: ram
                .parse()
                .with_context(|| format!("bad size in `{line}`"))?,
        });
    }
    if rows.is_empty() {
        bail!("the bench table is empty");
    }
    Ok(rows)
}

/// The firmware's bench binaries: the tracker's hot paths, paper 004's navigation filters
/// (a binary of their own for the stack the dense reference needs), and plot extraction (its
/// own for the extractor's RAM).
pub const BENCH_BINARIES: [&str; 3] = ["bench", "bench-nav", "bench-radar"];

/// Runs the given bench ELFs in turn, or (none given) builds and runs every one of
/// [`BENCH_BINARIES`], and returns the rows.
///
/// # Errors
/// QEMU missing, the build failing, the binary failing or running past five minutes, or its output not a bench table.
pub fn run(elfs: &[PathBuf]) -> anyhow::Result<Vec<BenchRow>> {
    let mut rows = Vec::new();
    if !elfs.is_empty() {
        for elf in elfs {
            rows.extend(run_one(&qemu::firmware_elf("bench", Some(elf))?)?);
        }
    } else {
        for bin in BENCH_BINARIES {
            rows.extend(run_one(&qemu::firmware_elf(bin, None)?)?);
        }
    }
    Ok(rows)
}

fn run_one(elf: &Path) -> anyhow::Result<Vec<BenchRow>> {
    let out = qemu::run_to_exit(elf, Duration::from_secs(300))?;
    parse(&out)
}

/// The table as CSV.
pub fn to_csv(rows: &[BenchRow]) -> String {
    let mut s = format!("{HEADER}\n");
    for r in rows {
        s += &format!(
            "{},{},{:.1},{}\n",
            r.name, r.scalar, r.instructions_per_call, r.ram_bytes
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_table_and_skips_noise() {
        let out = format!("boot\n{HEADER}\nlink-hello,-,5872.2,3148\nalpha-beta,f32,24.0,40\n");
        let rows = parse(&out).unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1].name, "alpha-beta");
        assert_eq!(rows[1].instructions_per_call, 24.0);
        assert_eq!(to_csv(&rows).lines().next(), Some(HEADER));
        assert!(parse("nothing").is_err());
        assert!(parse(&format!("{HEADER}\nx,f32,many,3\n")).is_err());
    }
}
