//! The machine's measured ceiling: a loop of fused multiply-adds in registers
//! on the widest f64 vectors, timed on each pool.

use super::options::Options;
use super::rows::{pool_rows, sampled_passes, Row};
use super::scenes::Work;

/// The scene name of the machine's own ceiling rows (`ceiling_rows`).
pub(super) const CEILING: &str = "fma ceiling";

/// Independent chains in the ceiling loop: more than the 8 that two FMA
/// units of 4 cycles' latency need to stay busy, few enough to stay in
/// registers (16 with AVX2, 32 with AVX-512).
pub(super) const CEILING_CHAINS: usize = 12;

/// The multiplier of each chain's `acc ← acc·m + 1`: below 1, so every
/// chain tends to 1 / (1 − m) = 1024 and stays a normal number.
const CEILING_FACTOR: f64 = 1.0 - 1.0 / 1024.0;

/// `rounds` rounds of `CEILING_CHAINS` fused multiply-adds on the widest
/// f64 vectors this processor has (pulp's choice, as the kernel's), with
/// nothing but registers: the most floating-point work a core of this
/// machine does, measured rather than assumed. Returns the sum of every
/// chain's lanes (chain k's each `k·mʳ + (1 − mʳ) / (1 − m)`) and the
/// flops done (2 per lane per fused multiply-add).
fn fma_ceiling(rounds: u64) -> (f64, u64) {
    pulp::Arch::new().dispatch(Ceiling { rounds })
}

struct Ceiling {
    rounds: u64,
}

impl pulp::WithSimd for Ceiling {
    type Output = (f64, u64);

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> (f64, u64) {
        let (m, one) = (simd.splat_f64s(CEILING_FACTOR), simd.splat_f64s(1.0));
        // Chain k starts at k: no two chains alike, so none can be merged.
        let mut chains: [S::f64s; CEILING_CHAINS] =
            std::array::from_fn(|k| simd.splat_f64s(k as f64));
        for _ in 0..std::hint::black_box(self.rounds) {
            for c in &mut chains {
                *c = simd.mul_add_f64s(*c, m, one);
            }
        }
        let sum = chains.iter().map(|&c| simd.reduce_sum_f64s(c)).sum();
        let flops = self.rounds * (CEILING_CHAINS * S::F64_LANES * 2) as u64;
        (sum, flops)
    }
}

/// The machine's ceiling on each of `pools`: `fma_ceiling` on every thread
/// of the pool at once, the same rounds shared among them, alternating
/// between pools, medians over `options.runs` samples of about 0.2 s on
/// the widest pool. Each row's GFLOP/s is what the loop did, its share of
/// the peak the nominal peak of its threads, its speed-up over the
/// one-thread pool the machine's own thread scaling: what the kernel's and
/// the renders' figures can be held against.
pub(super) fn ceiling_rows(
    pools: &[(usize, rayon::ThreadPool)],
    options: &Options,
    base: Row,
) -> Vec<Row> {
    // `rounds` shared among the pool's threads: the flops done.
    let pass = |pool: &rayon::ThreadPool, rounds: u64| -> u64 {
        let share = rounds.div_ceil(pool.current_num_threads() as u64);
        let done = pool.broadcast(|_| fma_ceiling(share));
        std::hint::black_box(done.iter().map(|d| d.0).sum::<f64>());
        done.iter().map(|d| d.1).sum()
    };
    let (_, walls, flops) = sampled_passes(pools, options, (1 << 16, 1 << 22), pass);
    let works: Vec<Work> = flops
        .into_iter()
        .map(|flops| Work {
            counted_flops: Some(flops),
            ..Work::default()
        })
        .collect();
    pool_rows(CEILING, pools, walls, &works, &options.peak, base)
}
#[cfg(test)]
mod tests {
    use super::super::peak::vector_lanes;
    use super::*;

    #[test]
    fn the_ceiling_loop_does_the_work_it_counts() {
        // Two flops per lane of each chain's fused multiply-add, each round.
        let per_round = (CEILING_CHAINS * 2) as u64;
        let lanes = fma_ceiling(1).1 / per_round;
        for rounds in [0, 1, 7, 5000] {
            let (sum, flops) = fma_ceiling(rounds);
            assert_eq!(flops, rounds * per_round * lanes);
            assert!([1, 2, 4, 8].contains(&lanes), "{lanes} lanes");
            // As wide as the peak counts (`Peak::lanes`).
            assert_eq!(lanes, vector_lanes() as u64);
            // Each lane of chain k: its start k shrunk by mʳ, plus the
            // geometric series 1 + m + … + mʳ⁻¹.
            let m = CEILING_FACTOR;
            let mr = m.powi(rounds as i32);
            let series = (1.0 - mr) / (1.0 - m);
            let chains: f64 = (0..CEILING_CHAINS).map(|k| k as f64 * mr + series).sum();
            let expected = chains * lanes as f64;
            let tolerance = 1e-9 * expected;
            assert!(
                (sum - expected).abs() <= tolerance,
                "{rounds}: {sum} vs {expected}"
            );
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // The loop runs on vectors as wide as the peak assumes.
            let (_, flops) = fma_ceiling(1);
            assert!(flops / (CEILING_CHAINS as u64 * 2) >= 4);
        }
    }
}
