//! The machine's floating-point peak: what the CPU reports (cores, clock,
//! vector width), the flops one kernel iteration counts, and a machine name.

/// Floating-point operations in one power-8 orbit iteration of the vector
/// kernel (`Fractal::estimate_lanes`, what rendering runs), counted from the
/// code, with a multiply, add, subtract, divide or square root each one
/// operation (comparisons, min and abs not counted): triplex power 50 (ρ²
/// and r² 5, ρ 1, the axis test 1, ρ⁸ from ρ² 2, its reciprocal 1, the
/// azimuth's cosine and sine scaled by it 2, two complex eighth powers by
/// three squarings of 6 each 36, the output 2); r⁷ 4; running derivative 3;
/// adding c 3; |z|² and |z| 6. The traps reuse |z|² and cost none.
pub(super) const FLOPS_PER_POWER8_ITERATION: u64 = 66;

/// FMA units per core: 2 on current x86 server cores (an assumption; the
/// CPU does not report it).
const FMA_UNITS: u32 = 2;

/// The machine's floating-point peak, from what the CPU reports.
#[derive(Clone, Debug)]
pub struct Peak {
    pub cpu: String,
    /// Physical cores: hyper-threads share their core's FMA units.
    pub cores: usize,
    pub clock_ghz: f64,
    /// f64 lanes of the widest vector unit (8 with AVX-512, 4 with AVX2, 2 with SSE2).
    pub lanes: u32,
}

impl Peak {
    /// cores × FMA units × lanes × 2 flops × clock, in GFLOP/s.
    pub fn gflops(&self) -> f64 {
        self.cores as f64 * FMA_UNITS as f64 * self.lanes as f64 * 2.0 * self.clock_ghz
    }

    /// The peak of `threads` threads: one core each, at most every core.
    pub fn gflops_for(&self, threads: usize) -> f64 {
        self.gflops() * threads.min(self.cores) as f64 / self.cores as f64
    }

    /// Reads the CPU model, clock and vector width of this machine.
    pub fn detect() -> Peak {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let field = |name: &str| {
            cpuinfo
                .lines()
                .find(|l| l.starts_with(name))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        };
        let clock_ghz = field("cpu MHz")
            .and_then(|v| v.parse::<f64>().ok())
            .map_or(0.0, |mhz| mhz / 1000.0);
        // Distinct (physical id, core id) pairs; logical CPUs where absent.
        let mut core_ids = std::collections::BTreeSet::new();
        let mut physical = "";
        for line in cpuinfo.lines() {
            if let Some((key, value)) = line.split_once(':') {
                match key.trim() {
                    "physical id" => physical = value.trim(),
                    "core id" => {
                        core_ids.insert((physical, value.trim()));
                    }
                    _ => {}
                }
            }
        }
        let logical = std::thread::available_parallelism().map_or(1, |n| n.get());
        let cores = if core_ids.is_empty() {
            logical
        } else {
            core_ids.len().min(logical)
        };
        Peak {
            cpu: field("model name").unwrap_or_else(|| std::env::consts::ARCH.to_string()),
            cores,
            clock_ghz,
            lanes: vector_lanes(),
        }
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) fn vector_lanes() -> u32 {
    if std::arch::is_x86_feature_detected!("avx512f") {
        8
    } else if std::arch::is_x86_feature_detected!("avx2") {
        4
    } else {
        2
    }
}

#[cfg(not(target_arch = "x86_64"))]
pub(super) fn vector_lanes() -> u32 {
    2 // 128-bit vectors (NEON and the like)
}

/// A file-name-safe default machine name: cores, CPU model and vector
/// width, so two machines that report one model name (AMD EPYCs with and
/// without AVX-512) keep their results apart.
pub fn default_machine_name(peak: &Peak) -> String {
    let model: String = peak
        .cpu
        .to_lowercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let model = model
        .split('-')
        .filter(|s| !s.is_empty() && *s != "r" && *s != "tm")
        .collect::<Vec<_>>()
        .join("-");
    let width = match peak.lanes {
        8 => "avx512",
        4 => "avx2",
        _ if cfg!(target_arch = "x86_64") => "sse",
        lanes => return format!("{}core-{model}-{lanes}lane", peak.cores),
    };
    format!("{}core-{model}-{width}", peak.cores)
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peak_is_the_product_of_its_factors() {
        let p = Peak {
            cpu: "test".into(),
            cores: 2,
            clock_ghz: 2.5,
            lanes: 4,
        };
        assert_eq!(p.gflops(), 2.0 * 2.0 * 4.0 * 2.0 * 2.5);
        // More threads than cores get no more peak.
        assert_eq!(p.gflops_for(1), p.gflops() / 2.0);
        assert_eq!(p.gflops_for(8), p.gflops());
        assert_eq!(default_machine_name(&p), "2core-test-avx2");
        let wide = Peak { lanes: 8, ..p };
        assert_eq!(default_machine_name(&wide), "2core-test-avx512");
    }
}
