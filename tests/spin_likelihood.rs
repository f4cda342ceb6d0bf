//! Unbinned likelihood fits of spin distributions (`rubblepile::analysis::spin_likelihood`) against SciPy 1.17.1.
//!
//! The samples and reference values were made by this script (SciPy's own `chi.fit`/`maxwell.fit` with their
//! default Nelder–Mead stop differ from the MLE by ~1e-8 relative even with tight tolerances, so the references
//! are `gamma.fit(x**2, floc=0)`, which solves the score equation, and the closed-form Maxwellian scale; both
//! agree with the tight `chi.fit`/`maxwell.fit` to < 2e-8):
//!
//! ```python
//! import numpy as np
//! from scipy import stats, optimize
//! rng = np.random.default_rng(57)
//! samples = {
//!   "maxwell_50": np.round(stats.maxwell.rvs(scale=2.0e-4, size=50, random_state=rng), 13),
//!   "chi_k1p3_120": np.round(stats.chi.rvs(1.3, scale=3.0e-4, size=120, random_state=rng), 13),
//!   "chi_k0p85_200": np.round(stats.chi.rvs(0.85, scale=1.0e-4, size=200, random_state=rng), 14),
//! }
//! tight = lambda f, x0, args=(), disp=0: optimize.fmin(f, x0, args, xtol=1e-13, ftol=1e-15,
//!                                                     maxiter=100000, maxfun=100000, disp=0)
//! def prof_k(x, k):  # profile log L in df, the scale maximised numerically
//!     r = optimize.minimize_scalar(lambda ls: -stats.chi.logpdf(x, k, 0, np.exp(ls)).sum(),
//!                                  bracket=(np.log(x.std())-1, np.log(x.std())+1), tol=1e-14)
//!     return -r.fun
//! def prof_s(x, s):
//!     r = optimize.minimize_scalar(lambda lk: -stats.chi.logpdf(x, np.exp(lk), 0, s).sum(),
//!                                  bracket=(-1, 1), tol=1e-14)
//!     return -r.fun
//! for name, x in samples.items():
//!     _, sm = stats.maxwell.fit(x, floc=0, optimizer=tight)
//!     sm_closed = np.sqrt(np.mean(x**2)/3)
//!     lm = stats.maxwell.logpdf(x, 0, sm).sum()
//!     lo = optimize.brentq(lambda s: stats.maxwell.logpdf(x, 0, s).sum() - (lm - 1.92), sm*0.5, sm,
//!                          xtol=1e-16, rtol=1e-14)
//!     hi = optimize.brentq(lambda s: stats.maxwell.logpdf(x, 0, s).sum() - (lm - 1.92), sm, sm*2,
//!                          xtol=1e-16, rtol=1e-14)
//!     ks = stats.kstest(x, stats.maxwell(0, sm).cdf)
//!     ad = stats.goodness_of_fit(stats.maxwell, x, known_params=dict(loc=0, scale=sm), statistic='ad',
//!                                n_mc_samples=99, rng=0)  # its statistic only (the p-value is Monte Carlo)
//!     k, _, s = stats.chi.fit(x, floc=0, optimizer=tight)
//!     a, _, sc = stats.gamma.fit(x**2, floc=0)
//!     k, s = 2*a, np.sqrt(sc/2)
//!     l = stats.chi.logpdf(x, k, 0, s).sum()
//!     klo = optimize.brentq(lambda kk: prof_k(x, kk) - (l - 1.92), k*0.2, k, xtol=1e-14, rtol=1e-13)
//!     khi = optimize.brentq(lambda kk: prof_k(x, kk) - (l - 1.92), k, k*5, xtol=1e-14, rtol=1e-13)
//!     slo = optimize.brentq(lambda ss: prof_s(x, ss) - (l - 1.92), s*0.3, s, xtol=1e-18, rtol=1e-13)
//!     shi = optimize.brentq(lambda ss: prof_s(x, ss) - (l - 1.92), s, s*3, xtol=1e-18, rtol=1e-13)
//!     ks = stats.kstest(x, stats.chi(k, 0, s).cdf)
//!     ad = stats.goodness_of_fit(stats.chi, x, known_params=dict(df=k, loc=0, scale=s), statistic='ad',
//!                                n_mc_samples=99, rng=0)
//! # KS p-values alone:
//! for d, n in [(0.1, 50), (0.25, 120), (0.05, 1000), (0.02, 5000), (0.3, 20), (0.6, 5)]:
//!     print(stats.kstwo.sf(d, n))
//! ```

use rubblepile::analysis::spin_likelihood::{
    LikelihoodFit, SpinLikelihood, Weights, ad_asymptotic_cdf, ad_p_value, chi_pdf, fit_spin_likelihood, ks_p_value,
};

#[rustfmt::skip]
const MAXWELL_50: [f64; 50] = [
    0.0003535873495, 0.0005504945819, 0.0003281474909, 0.0001543014388, 0.0003518655979,
    0.0001984850115, 0.0003811682471, 0.0001649289492, 0.0005142082297, 0.0004414647685,
    0.0002059474957, 0.0001368433168, 0.0002779162922, 0.0003823790391, 9.56119311e-05,
    0.0004430300403, 0.0003848412941, 0.0005394859978, 5.52436954e-05, 0.0002419205977,
    0.0001860410922, 0.0001926691053, 0.0002080221455, 0.000200037072, 0.0003406737276,
    0.0001855721458, 0.0001645622221, 0.0003324797273, 0.0005396376371, 0.0002686706921,
    0.000377503193, 0.0005023008473, 0.0002090723231, 0.0001400665907, 0.0002285270883,
    0.0004004090272, 0.0001236011782, 0.0002480367695, 0.0003668603336, 0.0001924898251,
    0.0003937287311, 0.0002318822658, 0.0002055990895, 0.0005158093961, 0.0003326225978,
    0.0003475513848, 0.0001197119687, 0.0002782507891, 0.0003621544604, 0.0002678179995,
];

#[rustfmt::skip]
const CHI_K1P3_120: [f64; 120] = [
    0.0006838932273, 0.0002073350993, 5.21865502e-05, 0.0002802802722, 8.80214804e-05,
    0.0001856349067, 0.0003153794926, 0.0002099810943, 0.0001789638704, 0.0006769552905,
    0.0001377027489, 0.0003262777186, 0.0001857140764, 0.0005797540227, 0.0006603575152,
    0.0001234161018, 5.14307186e-05, 0.0002463725473, 0.000120458322, 0.0007114498044,
    0.0007536648512, 0.0001119071833, 0.0004796058384, 0.0007347143219, 0.0003967782539,
    0.0001724743969, 0.0001293765174, 0.0003103640406, 0.0003099034719, 0.0008902624135,
    0.000691358915, 4.57661751e-05, 9.15163467e-05, 0.0004182296408, 0.0002259545383,
    0.0003610704602, 0.0001145178267, 6.57930323e-05, 0.0002740196598, 6.39196186e-05,
    0.0004140164813, 0.0003381731219, 0.0004598323544, 3.47906e-05, 7.78630157e-05,
    0.0002931583276, 0.0004326353855, 4.92922533e-05, 0.0002525721128, 0.0005734985897,
    0.0005592390468, 9.32004611e-05, 0.0002566953124, 0.0001780204195, 0.0007841970146,
    6.27016414e-05, 0.0002245044095, 0.0004061410378, 1.47805235e-05, 0.0004258891773,
    0.0004843842374, 0.0002486052119, 0.0004513286623, 0.0008239863528, 0.0001478899456,
    0.0001452270068, 0.0002976537725, 2.0556453e-05, 0.0004796453396, 0.0001810510116,
    0.0001612166538, 0.0002974931356, 0.0001316428818, 0.0002120303974, 0.0002184103835,
    0.0003809722107, 0.0002538506072, 0.0002301055603, 0.0003204155165, 0.000151604403,
    0.0001375850385, 7.36816983e-05, 0.0001616955818, 0.0002112325897, 0.0001143088182,
    0.0002387235626, 7.6590101e-06, 7.57227663e-05, 0.0005078984117, 0.0005737728042,
    0.0005457335593, 9.64228744e-05, 0.0004413277604, 0.0002285225034, 0.0002828046489,
    0.000477311806, 0.0001262593574, 0.0002145772207, 0.0003326344474, 0.0001062632384,
    6.93985733e-05, 0.0004496531833, 0.0004780646775, 0.0004672724383, 0.0001060154465,
    0.0007006051395, 0.0002694513984, 0.0002724929133, 0.0001221120965, 0.0002102697303,
    0.0001594754186, 0.0001460012889, 0.0005048027426, 0.0004737539436, 0.0002239571531,
    0.0005038655775, 0.0004167742088, 4.53287403e-05, 0.0001520799908, 0.0007603699849,
];

#[rustfmt::skip]
const CHI_K0P85_200: [f64; 200] = [
    3.77171688e-05, 4.341862649e-05, 0.00012321585522, 0.0001278643784, 5.857423616e-05,
    2.917561673e-05, 0.00011693701907, 2.614719185e-05, 0.00012256460378, 5.04529001e-06,
    4.90186249e-05, 2.22240073e-05, 4.835664596e-05, 0.0002256335085, 0.00012564037432,
    1.973522024e-05, 0.00011009703154, 6.022711595e-05, 4.551092183e-05, 0.00014843825381,
    2.661462402e-05, 7.752883019e-05, 1.30277831e-05, 0.00013722605966, 6.84317052e-06,
    3.953551444e-05, 0.00015821805996, 0.0001237456021, 0.00019957066266, 6.62127837e-06,
    0.00012613278953, 9.933453773e-05, 6.954885245e-05, 6.486951355e-05, 7.196583797e-05,
    0.00011870722237, 0.00015382524453, 2.250280568e-05, 3.784557579e-05, 6.907929249e-05,
    3.00342453e-05, 0.00019897556731, 3.071547617e-05, 4.227049043e-05, 6.289237569e-05,
    4.20131428e-06, 2.239116733e-05, 0.00011102702521, 5.772799562e-05, 1.081651184e-05,
    0.00011183213443, 0.00013644956595, 9.97814579e-05, 9.281983434e-05, 8.349062278e-05,
    9.930408501e-05, 6.884617284e-05, 5.98032611e-06, 7.29699848e-05, 3.827592863e-05,
    5.55342094e-06, 0.00010456579523, 1.98609656e-06, 6.277156731e-05, 6.049045952e-05,
    3.39302583e-06, 0.00022653614963, 7.4362254e-07, 1.029613318e-05, 0.00010077083319,
    8.991484028e-05, 2.459335025e-05, 9.619141276e-05, 5.11011979e-06, 8.192577009e-05,
    7.121570638e-05, 9.711275074e-05, 0.00013818637072, 0.00012518220844, 2.437575113e-05,
    0.00012109599204, 8.598068231e-05, 1.471680258e-05, 6.099265213e-05, 4.200966251e-05,
    0.00010848300161, 2.710185233e-05, 7.053285259e-05, 5.312661898e-05, 1.111015201e-05,
    6.772290989e-05, 9.335552795e-05, 1.48992365e-05, 0.00020624612467, 0.00011657935035,
    0.00010025291009, 9.342851731e-05, 6.34628095e-05, 1.903798542e-05, 8.404742678e-05,
    4.840203194e-05, 3.196028421e-05, 1.672026458e-05, 0.00018488089236, 9.414557505e-05,
    9.274311922e-05, 3.618367221e-05, 0.00010397687675, 2.346030196e-05, 1.413471294e-05,
    0.00011572346931, 3.921926326e-05, 0.00030259498058, 1.46943933e-05, 8.012379907e-05,
    1.73125755e-06, 2.13855012e-06, 3.879074707e-05, 0.00012825963017, 4.540303e-06,
    5.963819502e-05, 0.00012242381214, 7.567784007e-05, 0.00021478877675, 7.969721306e-05,
    0.000114141201, 0.00019180075014, 4.83581136e-06, 0.0001548069323, 5.884916604e-05,
    4.819855943e-05, 5.062373e-08, 0.00011746161061, 0.0001187482658, 5.466004502e-05,
    0.00012172458702, 2.530426794e-05, 1.476192854e-05, 0.00020648157193, 8.508811505e-05,
    0.00013850842952, 1.027749123e-05, 0.00015783628938, 2.97069318e-05, 6.3126191e-07,
    9.632728538e-05, 3.09374062e-05, 5.561302571e-05, 0.00020289286852, 7.549660677e-05,
    6.886873808e-05, 0.00014430613838, 0.00013064020718, 2.986985398e-05, 7.131964112e-05,
    3.503010044e-05, 0.0001347075794, 5.134263737e-05, 0.00024696999737, 5.638718054e-05,
    0.00013756200583, 5.603043578e-05, 3.88761e-05, 8.110427012e-05, 7.492910306e-05,
    5.129631099e-05, 0.00012313088918, 1.962767052e-05, 3.046058503e-05, 1.9037192e-07,
    6.189831945e-05, 2.775681125e-05, 7.69863248e-06, 8.02248998e-06, 3.064295996e-05,
    0.00023358099521, 0.00012793971262, 0.00022282536544, 3.192770373e-05, 0.00013742623135,
    0.00014150693659, 8.797429896e-05, 7.53775159e-05, 3.588673431e-05, 0.00023718904333,
    6.144504409e-05, 3.877754449e-05, 0.00017173741076, 2.633048681e-05, 1.651123583e-05,
    0.00014558954323, 4.66214691e-06, 7.259691589e-05, 3.211591707e-05, 0.00012187794336,
    0.00012840570017, 7.586529473e-05, 5.219758539e-05, 4.870905981e-05, 0.00015387358198,
];

/// SciPy's numbers for one sample.
struct Reference {
    maxwell_sigma: f64,
    maxwell_sigma_closed: f64,
    maxwell_log_l: f64,
    maxwell_sigma_interval: [f64; 2],
    maxwell_ks: [f64; 2],
    maxwell_a2: f64,
    n: f64,
    sigma: f64,
    log_l: f64,
    n_interval: [f64; 2],
    sigma_interval: [f64; 2],
    ks: [f64; 2],
    a2: f64,
}

const REF_MAXWELL_50: Reference = Reference {
    maxwell_sigma: 0.0001846464397439302,
    maxwell_sigma_closed: 0.00018464644063555344,
    maxwell_log_l: 379.0020476859778,
    maxwell_sigma_interval: [0.00016557368506765454, 0.00020768290917592028],
    maxwell_ks: [0.11339544042116262, 0.5052299849120762],
    maxwell_a2: 0.5067934145023685,
    n: 1.8525352886155604,
    sigma: 0.00018935904507254213,
    log_l: 379.0412177437543,
    n_interval: [0.9631768229132875, 3.0001208887560242],
    sigma_interval: [0.0001555400061059175, 0.0002386089857942072],
    ks: [0.10342848340697364, 0.6212861563365337],
    a2: 0.4391566393556374,
};

const REF_CHI_K1P3_120: Reference = Reference {
    maxwell_sigma: 0.0002098095407188461,
    maxwell_sigma_closed: 0.00020980953812577662,
    maxwell_log_l: 819.8873180861273,
    maxwell_sigma_interval: [0.0001953720753691785, 0.0002261168129085877],
    maxwell_ks: [0.24507599760576607, 7.836510009427895e-07],
    maxwell_a2: 22.363296471316232,
    n: 0.22075241415365232,
    sigma: 0.00032890619924265884,
    log_l: 864.9062288175985,
    n_interval: [-0.019350813821616075, 0.5011587008775249],
    sigma_interval: [0.0002838984575886925, 0.00038866812899653795],
    ks: [0.05910313893299107, 0.7733480040434207],
    a2: 0.494685156173432,
};

const REF_CHI_K0P85_200: Reference = Reference {
    maxwell_sigma: 5.672050470837484e-05,
    maxwell_sigma_closed: 5.672050458148107e-05,
    maxwell_log_l: 1545.45351991044,
    maxwell_sigma_interval: [5.365711560079023e-05, 6.008687346368239e-05],
    maxwell_ks: [0.26699077690453193, 4.457128708470429e-13],
    maxwell_a2: 55.18501992998952,
    n: -0.09339504946992283,
    sigma: 0.00010317908445499506,
    log_l: 1701.1933169080212,
    n_interval: [-0.23042472408545034, 0.06057898382565452],
    sigma_interval: [9.114733592692655e-05, 0.00011841861941340347],
    ks: [0.03546572432901984, 0.9552247589883003],
    a2: 0.4084965614166549,
};

fn close(ours: f64, theirs: f64, rel: f64, what: &str) {
    assert!(
        (ours - theirs).abs() <= rel * theirs.abs(),
        "{what}: {ours} vs SciPy {theirs} (rel. {:.2e})",
        (ours - theirs).abs() / theirs.abs()
    );
}

fn check(x: &[f64], r: &Reference, name: &str) -> SpinLikelihood {
    let fit = fit_spin_likelihood(x, Weights::Number).unwrap();
    assert_eq!(
        (fit.samples, fit.skipped, fit.weighting),
        (x.len(), 0, "number"),
        "{name}"
    );
    let (m, f) = (&fit.maxwellian, &fit.free);
    // Parameters and log-likelihoods: 1e-6 relative (the interval ends in n as k = n + 1, n being near 0).
    close(
        m.sigma,
        r.maxwell_sigma_closed,
        1e-12,
        &format!("{name} Maxwellian σ (closed form)"),
    );
    close(
        m.sigma,
        r.maxwell_sigma,
        1e-6,
        &format!("{name} Maxwellian σ (maxwell.fit)"),
    );
    assert_eq!(m.n, 2.0);
    assert!(m.n_interval.is_none());
    close(
        m.log_likelihood,
        r.maxwell_log_l,
        1e-9,
        &format!("{name} Maxwellian ln L"),
    );
    for j in 0..2 {
        close(
            m.sigma_interval[j],
            r.maxwell_sigma_interval[j],
            1e-6,
            &format!("{name} Maxwellian σ interval"),
        );
        close(
            f.sigma_interval[j],
            r.sigma_interval[j],
            1e-6,
            &format!("{name} free σ interval"),
        );
        let ni = f.n_interval.unwrap();
        close(
            ni[j] + 1.0,
            r.n_interval[j] + 1.0,
            1e-6,
            &format!("{name} free n interval (as k)"),
        );
    }
    close(f.n + 1.0, r.n + 1.0, 1e-6, &format!("{name} free k = n + 1"));
    assert!(
        (f.n - r.n).abs() <= 1e-6 * r.n.abs().max(1.0),
        "{name}: n {} vs {}",
        f.n,
        r.n
    );
    close(f.sigma, r.sigma, 1e-6, &format!("{name} free σ"));
    close(
        f.b,
        std::f64::consts::SQRT_2 * r.sigma,
        1e-6,
        &format!("{name} Eq. 44 b"),
    );
    close(f.log_likelihood, r.log_l, 1e-9, &format!("{name} free ln L"));
    // Goodness of fit: statistics 1e-6 relative, p-values 1e-3 absolute.
    for (g, ks, a2, what) in [
        (&m.goodness, r.maxwell_ks, r.maxwell_a2, "Maxwellian"),
        (&f.goodness, r.ks, r.a2, "free"),
    ] {
        close(g.ks_d, ks[0], 1e-6, &format!("{name} {what} KS D"));
        assert!(
            (g.ks_p - ks[1]).abs() <= 1e-3 && (g.ks_p - ks[1]).abs() <= 1e-3 * ks[1].max(1e-3),
            "{name} {what} KS p {} vs {}",
            g.ks_p,
            ks[1]
        );
        close(g.ad_a2, a2, 1e-6, &format!("{name} {what} AD A²"));
        assert!((0.0..=1.0).contains(&g.ad_p));
    }
    fit
}

#[test]
fn maxwellian_sample_matches_scipy_and_is_not_rejected() {
    let fit = check(&MAXWELL_50, &REF_MAXWELL_50, "maxwell_50");
    // n = 2 lies inside the free fit's interval; neither test rejects the Maxwellian
    let ni = fit.free.n_interval.unwrap();
    assert!(ni[0] < 2.0 && 2.0 < ni[1]);
    assert!(fit.maxwellian.goodness.ks_p > 0.1 && fit.maxwellian.goodness.ad_p > 0.1);
}

#[test]
fn chi_k1p3_sample_matches_scipy() {
    let fit = check(&CHI_K1P3_120, &REF_CHI_K1P3_120, "chi_k1p3_120");
    assert!(fit.maxwellian.goodness.ks_p < 1e-3 && fit.maxwellian.goodness.ad_p < 1e-3);
}

#[test]
fn chi_k0p85_sample_matches_scipy_and_the_summary_says_what_was_fitted() {
    let fit = check(&CHI_K0P85_200, &REF_CHI_K0P85_200, "chi_k0p85_200");
    assert!(fit.maxwellian.goodness.ks_p < 1e-3 && fit.maxwellian.goodness.ad_p < 1e-3);
    // The console line reports the free exponent (≈ −0.09), never a rounded "n = 1" (issue 57).
    let line = fit.summary_line();
    assert!(line.contains("free n = -0.093 [-0.230, 0.061]"), "{line}");
    assert!(
        line.contains("Maxwellian n = 2") && line.contains("KS p = 4.5e-13"),
        "{line}"
    );
}

/// Σ ln f(ωᵢ) computed from the public density, independently of the fit's own bookkeeping.
fn log_l(x: &[f64], n: f64, sigma: f64) -> f64 {
    x.iter().map(|&v| chi_pdf(v, n + 1.0, sigma).ln()).sum()
}

#[test]
fn the_likelihood_is_maximal_at_the_fit() {
    for x in [&MAXWELL_50[..], &CHI_K1P3_120[..], &CHI_K0P85_200[..]] {
        let fit = fit_spin_likelihood(x, Weights::Number).unwrap();
        let f: &LikelihoodFit = &fit.free;
        let l0 = log_l(x, f.n, f.sigma);
        assert!((l0 - f.log_likelihood).abs() <= 1e-9 * l0.abs());
        // central differences of ln L vanish (relative to the curvature scale), and every neighbour is lower
        for (dn, ds) in [(1e-4, 0.0), (0.0, 1e-4 * f.sigma)] {
            let (lp, lm) = (log_l(x, f.n + dn, f.sigma + ds), log_l(x, f.n - dn, f.sigma - ds));
            assert!(lp < l0 && lm < l0);
            let slope = (lp - lm) / 2.0;
            let curvature = l0 - 0.5 * (lp + lm);
            assert!(slope.abs() < 1e-3 * curvature, "slope {slope}, curvature {curvature}");
        }
        // the Maxwellian: σ maximises ln L at n = 2
        let m = &fit.maxwellian;
        let l0 = log_l(x, 2.0, m.sigma);
        let h = 1e-4 * m.sigma;
        let (lp, lm) = (log_l(x, 2.0, m.sigma + h), log_l(x, 2.0, m.sigma - h));
        assert!(lp < l0 && lm < l0 && ((lp - lm) / 2.0).abs() < 1e-3 * (l0 - 0.5 * (lp + lm)));
        // the interval ends lie 1.92 below the maximum of the profile
        let ni = f.n_interval.unwrap();
        for nn in ni {
            let k = nn + 1.0;
            let sigma_k = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64 / k).sqrt();
            assert!((f.log_likelihood - log_l(x, nn, sigma_k) - 1.92).abs() < 1e-6);
        }
    }
}

#[test]
fn equal_masses_give_the_unweighted_fit_and_unequal_ones_move_it() {
    let x = &CHI_K1P3_120[..];
    let by_number = fit_spin_likelihood(x, Weights::Number).unwrap();
    let masses = vec![3.7e9; x.len()];
    let by_mass = fit_spin_likelihood(x, Weights::Mass(&masses)).unwrap();
    assert_eq!(by_mass.weighting, "mass");
    for (a, b) in [
        (&by_number.free, &by_mass.free),
        (&by_number.maxwellian, &by_mass.maxwellian),
    ] {
        for (p, q) in [
            (a.n, b.n),
            (a.sigma, b.sigma),
            (a.log_likelihood, b.log_likelihood),
            (a.sigma_interval[0], b.sigma_interval[0]),
            (a.sigma_interval[1], b.sigma_interval[1]),
            (a.goodness.ks_p, b.goodness.ks_p),
            (a.goodness.ad_a2, b.goodness.ad_a2),
        ] {
            assert!((p - q).abs() <= 1e-10 * p.abs().max(1e-300), "{p} vs {q}");
        }
    }
    // doubling each rate's weight by repeating it: weights 2 = the sample listed twice (same fit)
    let twice: Vec<f64> = x.iter().chain(x).copied().collect();
    let w: Vec<f64> = (0..x.len()).map(|i| if i % 2 == 0 { 2.0 } else { 1.0 }).collect();
    let repeated: Vec<f64> = x
        .iter()
        .enumerate()
        .flat_map(|(i, &v)| vec![v; if i % 2 == 0 { 2 } else { 1 }])
        .collect();
    let weighted = fit_spin_likelihood(x, Weights::Mass(&w)).unwrap();
    let plain = fit_spin_likelihood(&repeated, Weights::Number).unwrap();
    assert!(
        (weighted.free.n - plain.free.n).abs() < 1e-9 && (weighted.free.sigma / plain.free.sigma - 1.0).abs() < 1e-12
    );
    assert!((weighted.free.n - by_number.free.n).abs() > 1e-4);
    assert_eq!(
        fit_spin_likelihood(&twice, Weights::Number).unwrap().samples,
        2 * x.len()
    );
}

#[test]
fn bad_input_is_refused_by_name() {
    let err = |x: &[f64], w: Weights| fit_spin_likelihood(x, w).unwrap_err().to_string();
    assert!(err(&[1.0, f64::NAN, 2.0], Weights::Number).contains("spin rates"));
    assert!(err(&[1.0, 2.0], Weights::Mass(&[1.0])).contains("1 masses for 2 spin rates"));
    assert!(err(&[1.0, 2.0], Weights::Mass(&[1.0, 0.0])).contains("masses"));
    assert!(err(&[0.0, 0.0, 1.0], Weights::Number).contains("too few points"));
    assert!(err(&[2.0, 2.0, 2.0], Weights::Number).contains("all (nearly) equal"));
    // rates ≤ 0 are left out and counted
    let mut x = CHI_K1P3_120.to_vec();
    x.extend([0.0, 0.0]);
    let fit = fit_spin_likelihood(&x, Weights::Number).unwrap();
    assert_eq!((fit.samples, fit.skipped), (120, 2));
}

#[test]
fn ks_p_values_match_scipy_kstwo() {
    for (d, n, p) in [
        (0.1, 50, 0.6623112704658186),
        (0.25, 120, 4.283039195002836e-07),
        (0.05, 1000, 0.013012074781090332),
        (0.02, 5000, 0.03613941395325637),
        (0.3, 20, 0.04306706665851623),
        (0.6, 5, 0.03008000000000001),
    ] {
        let ours = ks_p_value(d, n);
        assert!((ours - p).abs() <= 1e-6 * p, "D {d}, N {n}: {ours} vs {p}");
    }
    assert_eq!(
        (ks_p_value(0.0, 10), ks_p_value(1.0, 10), ks_p_value(0.01, 10)),
        (1.0, 0.0, 1.0)
    );
}

#[test]
fn ad_p_values_match_the_published_asymptotic_percentage_points() {
    // Upper percentage points of the asymptotic A² for a fully specified distribution (Anderson & Darling 1954;
    // Stephens 1974, Table 1, case 0). Measured: 0.24996, 0.100006, 0.050014, 0.02522, 0.01024 — the 1 % point 3.857
    // of the 1954 table sits at p = 0.01024 by this evaluation (p = 0.0100 at A² = 3.878), inside 1e-3.
    for (a2, p) in [
        (1.248, 0.25),
        (1.933, 0.10),
        (2.492, 0.05),
        (3.070, 0.025),
        (3.857, 0.01),
    ] {
        let ours = ad_p_value(a2);
        assert!((ours - p).abs() <= 1e-3, "A² {a2}: p {ours} vs {p}");
    }
    assert_eq!((ad_asymptotic_cdf(0.0), ad_asymptotic_cdf(f64::INFINITY)), (0.0, 1.0));
    // the two branches meet at A² = 2 (to the approximation's accuracy), and the tail stays positive
    assert!((ad_asymptotic_cdf(2.0 - 1e-12) - ad_asymptotic_cdf(2.0)).abs() < 2e-6);
    // beyond 8, √3 erfc(√A²): 1.6972e-25 at 55 (Python: math.sqrt(3)*math.erfc(math.sqrt(55))), and
    // within 1.5 % of the polynomial at the switch
    assert!((ad_p_value(55.0) / 1.697249376142741e-25 - 1.0).abs() < 1e-6);
    assert!((ad_p_value(8.0) / ad_p_value(8.0 - 1e-9) - 1.0).abs() < 0.015);
    assert!(ad_p_value(7.9) > ad_p_value(8.0) && ad_p_value(8.0) > ad_p_value(8.1));
}
