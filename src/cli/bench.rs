//! `bench`: times the benchmark scenes, and compares them with Mandelbulber2
//! where it is installed.

use super::BenchArgs;
use crate::error::Error;
use crate::job::request::parse_size;

/// `bench`: checks the options, runs the benchmark, prints the tables.
pub fn bench(args: BenchArgs) -> anyhow::Result<()> {
    let peak = crate::bench::Peak::detect();
    let logical_cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let memory_size = match args.memory_size.as_str() {
        "none" => None,
        text => Some(parse_size("--memory-size", text)?),
    };
    let depth_size = match args.depth_size.as_str() {
        "none" => None,
        text => Some(parse_size("--depth-size", text)?),
    };
    if args.runs == 0 {
        return Err(Error::usage("--runs", "must be at least 1").into());
    }
    let threads = if args.threads.is_empty() {
        let mut t: Vec<usize> = std::iter::successors(Some(1), |n| Some(n * 2))
            .take_while(|&n| n < logical_cpus)
            .collect();
        t.push(logical_cpus);
        t
    } else {
        args.threads.clone()
    };
    if threads.contains(&0) {
        return Err(Error::usage("--threads", "thread counts must be at least 1").into());
    }
    let mandelbulber = (!args.no_mandelbulber)
        .then(|| {
            std::process::Command::new(&args.mandelbulber)
                .arg("--version")
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .status()
                .is_ok_and(|s| s.success())
                .then(|| args.mandelbulber.clone())
        })
        .flatten();
    if mandelbulber.is_none() && !args.quiet {
        eprintln!(
            "Mandelbulber2 not compared ({}): install it (Debian: apt-get install mandelbulber2) for the A/B rows",
            if args.no_mandelbulber { "--no-mandelbulber" } else { "not found" }
        );
    }
    let options = crate::bench::Options {
        scenes: args.scenes,
        fract_dir: args.fract_dir,
        mandelbulber,
        runs: args.runs,
        threads,
        memory_size,
        depth_size,
        results: args.results.clone(),
        machine: args
            .machine
            .unwrap_or_else(|| crate::bench::default_machine_name(&peak)),
        peak,
        quiet: args.quiet,
    };
    let md = crate::bench::run_and_write(&options)?;
    out!("{md}");
    out!(
        "written: {}",
        options
            .results
            .join(format!("{}.csv", options.machine))
            .display()
    );
    Ok(())
}
