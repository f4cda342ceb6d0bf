//! The r⁻³ radius law of Zhang17's polydisperse models (Table 2: PP1 4–32 m, PP2 4–16 m) against its CDF with a
//! Kolmogorov–Smirnov test; the test has power: a wrong exponent is rejected.

use rubblepile::aggregate::size_distribution::PowerLawRadii;
use rubblepile::random::generator;
use statrs::stats_tests::NaNPolicy;
use statrs::stats_tests::ks_test::{KSOneSampleAlternativeMethod, ks_onesample};

#[test]
fn inverse_cube_sampler_passes_ks_against_its_cdf() {
    let law = PowerLawRadii::inverse_cube(4.0, 32.0).unwrap();
    let mut rng = generator(11);
    let sample: Vec<f64> = (0..20_000).map(|_| law.sample(&mut rng)).collect();
    assert!(sample.iter().all(|&r| (4.0..=32.0).contains(&r)));
    let ks = |d: &PowerLawRadii| {
        ks_onesample(
            sample.clone(),
            d,
            KSOneSampleAlternativeMethod::TwoSidedAsymptotic,
            NaNPolicy::Error,
        )
        .unwrap()
    };
    let (stat, p) = ks(&law);
    assert!(p > 0.01, "D = {stat}, p = {p}");
    let wrong = PowerLawRadii { exponent: -2.5, ..law };
    let (_, p_wrong) = ks(&wrong);
    assert!(p_wrong < 1e-6, "a −2.5 law was not rejected: p = {p_wrong}");
    // the mean volume factor ⟨r³⟩ against the sample
    let m3 = sample.iter().map(|r| r.powi(3)).sum::<f64>() / sample.len() as f64;
    assert!((m3 / law.moment(3.0) - 1.0).abs() < 0.05, "{m3} vs {}", law.moment(3.0));
    // ⟨r³⟩ of r⁻³ on [a, b] is 2 a² b² (b − a)/(b² − a²) … exactly: 2(b − a)/(a⁻² − b⁻²)
    assert!((law.moment(3.0) - 2.0 * 28.0 / (1.0 / 16.0 - 1.0 / 1024.0)).abs() < 1e-9);
}
