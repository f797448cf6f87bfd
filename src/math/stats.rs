//! Summaries of measured values.

/// The median of `values` (the mean of the middle two for an even count;
/// 0 for none). Reorders `values`.
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// Peak signal-to-noise ratio of a mean squared error `mse` against a
/// signal whose peak is `peak` (255 for 8-bit codes, 1 for unit values):
/// 10·log10(peak²/mse) dB; +∞ for identical signals (mse 0).
pub fn psnr_db(mse: f64, peak: f64) -> f64 {
    if mse <= 0.0 {
        return f64::INFINITY;
    }
    10.0 * (peak * peak / mse).log10()
}

/// `psnr_db` of a root-mean-square error: 20·log10(peak/rmse) dB, taken
/// as 20·(log10 peak − log10 rmse), so an RMSE that squaring would
/// underflow still has its figure.
pub fn psnr_db_of_rmse(rmse: f64, peak: f64) -> f64 {
    if rmse <= 0.0 {
        return f64::INFINITY;
    }
    20.0 * (peak.log10() - rmse.log10())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts_and_of_none() {
        assert_eq!(median(&mut [5.0, 1.0, 3.0]), 3.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [1.0, 1.0, 9.0, 1.0, 0.5]), 1.0);
        assert_eq!(median(&mut []), 0.0);
    }

    #[test]
    fn psnr_of_known_errors_in_either_unit() {
        assert_eq!(psnr_db(0.0, 1.0), f64::INFINITY);
        assert!((psnr_db(0.01, 1.0) - 20.0).abs() < 1e-12);
        assert!((psnr_db(1e-4, 1.0) - 40.0).abs() < 1e-12);
        assert!((psnr_db(1.0, 255.0) - 48.1308).abs() < 1e-4);
        assert!((psnr_db(4.0, 255.0) - 42.1102).abs() < 1e-4);
        assert_eq!(psnr_db_of_rmse(0.0, 1.0), f64::INFINITY);
        assert_eq!(psnr_db_of_rmse(0.1, 1.0), -20.0 * 0.1f64.log10());
        assert!((psnr_db_of_rmse(2.0, 255.0) - psnr_db(4.0, 255.0)).abs() < 1e-12);
        assert_eq!(psnr_db_of_rmse(1e-200, 1.0), 4000.0);
    }
}
