//! `scallop-fuzz`: long fuzzing campaigns over every target (docs/fuzzing.md).
//!
//! ```text
//! scallop-fuzz [--iterations N] [--seed S] [--targets stl,gcode,...] [--timeout SECONDS]
//!              [--max-rss-mb MB] [--save DIR]
//! scallop-fuzz --repro TARGET ITERATION [--seed S] --save DIR
//! ```
//!
//! Runs N inputs per target. A watchdog stops the run (exit code 3) when one input takes
//! longer than the timeout (default 10 s) or the resident memory passes the cap (default
//! 2048 MB), naming the target and iteration; failures (panics, broken promises) are
//! listed and saved, exit code 1. The peak resident memory (`VmHWM`) is printed at the end.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use scallop_fuzz::{Target, campaign, input, seeds};

fn status_kb(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

struct Options {
    iterations: u64,
    seed: u64,
    targets: Vec<Target>,
    timeout: f64,
    max_rss_mb: u64,
    save: Option<std::path::PathBuf>,
    repro: Option<(Target, u64)>,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        iterations: 10_000,
        seed: 21,
        targets: Target::ALL.to_vec(),
        timeout: 10.0,
        max_rss_mb: 2048,
        save: None,
        repro: None,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut k = 0;
    let value = |k: usize| args.get(k + 1).cloned().ok_or_else(|| format!("{} needs a value", args[k]));
    while k < args.len() {
        match args[k].as_str() {
            "--iterations" => o.iterations = value(k)?.parse().map_err(|e| format!("--iterations: {e}"))?,
            "--seed" => o.seed = value(k)?.parse().map_err(|e| format!("--seed: {e}"))?,
            "--timeout" => o.timeout = value(k)?.parse().map_err(|e| format!("--timeout: {e}"))?,
            "--max-rss-mb" => o.max_rss_mb = value(k)?.parse().map_err(|e| format!("--max-rss-mb: {e}"))?,
            "--save" => o.save = Some(value(k)?.into()),
            "--targets" => {
                o.targets = value(k)?
                    .split(',')
                    .map(|n| Target::from_name(n).ok_or_else(|| format!("unknown target `{n}`")))
                    .collect::<Result<_, _>>()?;
            }
            "--repro" => {
                let t = Target::from_name(&value(k)?).ok_or("--repro: unknown target")?;
                let i =
                    args.get(k + 2).ok_or("--repro TARGET ITERATION")?.parse().map_err(|e| format!("--repro: {e}"))?;
                o.repro = Some((t, i));
                k += 1;
            }
            other => return Err(format!("unknown argument `{other}`")),
        }
        k += 2;
    }
    Ok(o)
}

fn main() -> std::process::ExitCode {
    let o = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("scallop-fuzz: {e}");
            return std::process::ExitCode::from(2);
        }
    };
    if let Some((target, iteration)) = o.repro {
        let bytes = input(target, &seeds(target), o.seed, iteration);
        let dir = o.save.clone().unwrap_or_else(|| ".".into());
        let path = dir.join(format!("{}-{}-{iteration}", target.name(), o.seed));
        if let Err(e) = std::fs::write(&path, &bytes) {
            eprintln!("{}: {e}", path.display());
            return std::process::ExitCode::from(2);
        }
        println!("{}: {:?}", path.display(), scallop_fuzz::run_one(target, &bytes));
        return std::process::ExitCode::SUCCESS;
    }
    // Quiet panics: they are caught and reported as failures.
    std::panic::set_hook(Box::new(|_| {}));
    let started = Instant::now();
    let current = Arc::new(AtomicU64::new(0)); // ms since start when the current input began
    let which = Arc::new(AtomicU64::new(0)); // target index << 40 | iteration
    {
        let (current, which) = (Arc::clone(&current), Arc::clone(&which));
        let (timeout, cap_kb) = (o.timeout, o.max_rss_mb * 1024);
        let seed = o.seed;
        std::thread::spawn(move || {
            loop {
                std::thread::sleep(Duration::from_millis(200));
                let now = u64::try_from(started.elapsed().as_millis()).unwrap_or(u64::MAX);
                let w = which.load(Ordering::Relaxed);
                let (t, i) = (Target::ALL[usize::try_from(w >> 40).unwrap_or(0)], w & ((1 << 40) - 1));
                #[allow(clippy::cast_precision_loss, reason = "milliseconds")]
                let took = now.saturating_sub(current.load(Ordering::Relaxed)) as f64 / 1000.0;
                if took > timeout {
                    eprintln!("HANG: target {} seed {seed} iteration {i} runs for over {timeout} s", t.name());
                    std::process::exit(3);
                }
                if let Some(rss) = status_kb("VmRSS:")
                    && rss > cap_kb
                {
                    eprintln!("MEMORY: target {} seed {seed} iteration {i}: {} MB resident", t.name(), rss / 1024);
                    std::process::exit(3);
                }
            }
        });
    }
    let mut failed = 0usize;
    let mut total = 0u64;
    for (index, &target) in Target::ALL.iter().enumerate().filter(|(_, t)| o.targets.contains(t)) {
        let t0 = Instant::now();
        let before = |iteration: u64| {
            which.store(((index as u64) << 40) | iteration, Ordering::Relaxed);
            current.store(u64::try_from(started.elapsed().as_millis()).unwrap_or(u64::MAX), Ordering::Relaxed);
        };
        let report = campaign(target, o.seed, 0..o.iterations, &before);
        total += report.executions;
        println!(
            "{:>8}: {} inputs ({} accepted) in {:.1} s, slowest {:.3} s (iteration {}), {} failures",
            target.name(),
            report.executions,
            report.accepted,
            t0.elapsed().as_secs_f64(),
            report.slowest.0.as_secs_f64(),
            report.slowest.1,
            report.failures.len()
        );
        for (iteration, message) in report.failures.iter().take(20) {
            println!("    FAIL {} iteration {iteration}: {message}", target.name());
            if let Some(dir) = &o.save {
                let bytes = input(target, &seeds(target), o.seed, *iteration);
                let _ = std::fs::create_dir_all(dir);
                let _ = std::fs::write(dir.join(format!("{}-{}-{iteration}", target.name(), o.seed)), bytes);
            }
        }
        failed += report.failures.len();
    }
    println!(
        "total: {total} inputs in {:.1} s, {failed} failures, peak resident memory {} MB",
        started.elapsed().as_secs_f64(),
        status_kb("VmHWM:").unwrap_or(0) / 1024
    );
    if failed > 0 { std::process::ExitCode::from(1) } else { std::process::ExitCode::SUCCESS }
}
