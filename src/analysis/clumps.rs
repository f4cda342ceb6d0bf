//! Clumps of any snapshot (ellipsoids, soft or hard spheres) and the largest remnant, as pkdgrav's companion and
//! friends-of-friends finders define them (Michel et al. 2001, Science 294; Leinhardt & Richardson 2002, Icarus 159).
//!
//! 1. Linking ([`crate::ellipsoid::clumps`]): friends when the surface gap is ≤ `f · min(cᵢ, cⱼ)` (`c` the smallest
//!    semi-axis, `f` = [`DEFAULT_GAP_FRACTION`]); exact for spheres, for ellipsoids none beyond `ℓ (aᵢ/cᵢ + aⱼ/cⱼ)/2`.
//! 2. Boundness (self-gravity only): member `i` of set `S` stays when `Eᵢ = ½ mᵢ |vᵢ − V|² M/(M − mᵢ) −
//!    G mᵢ Σ_{j≠i} mⱼ/|rᵢ − rⱼ| < 0` (exact two-body energy for two bodies; pairwise, no monopole). Each pass drops the
//!    most unbound quarter (≥ 1) as SUBFIND does (Springel et al. 2001, MNRAS 328), re-links kept and dropped
//!    members and refines again to a fixed point (strict subsets each pass, so it ends).
//! 3. Per clump: mass, centre of mass, `I = Σ (Rᵢᵀ Iᵢ Rᵢ + mᵢ(|dᵢ|² 1 − dᵢ dᵢᵀ))`, `L = Σ (mᵢ dᵢ × uᵢ + Rᵢᵀ Iᵢ ωᵢ)`,
//!    `ω = I⁻¹ L`, and the equivalent uniform ellipsoid `a² = 5 (I₂ + I₃ − I₁)/(2M)` (cyclic), as `b/a`, `c/a`.
//! 4. Fate: the heaviest is `largest`; another is `bound` when `½ μ |Vₖ − V₀|² − G Mₖ M₀/|Rₖ − R₀| < 0`, else
//!    `escaping` (always without self-gravity).

use rayon::prelude::*;

use crate::ellipsoid::body::Body;
pub use crate::ellipsoid::clumps::{DEFAULT_GAP_FRACTION, find_clumps};
use crate::ellipsoid::clumps::{Linking, find_clumps_among};
use crate::ellipsoid::quaternion::rotation_matrix;
use crate::math::{Mat3, Vec3};

/// The mass-weighted mean of `f(body)` over the bodies `ids`, whose mass is `mass` (kg).
pub(crate) fn mass_mean(bodies: &[Body], ids: &[usize], mass: f64, f: impl Fn(&Body) -> Vec3) -> Vec3 {
    ids.iter().map(|&i| f(&bodies[i]) * bodies[i].shape.mass).sum::<Vec3>() / mass
}

/// The energy `Eᵢ` of each member of `ids` against the rest of the set (module docs, item 2), with `g` (SI).
fn member_energies(bodies: &[Body], ids: &[usize], g: f64) -> Vec<f64> {
    let mass: f64 = ids.iter().map(|&i| bodies[i].shape.mass).sum();
    let v = mass_mean(bodies, ids, mass, |b| b.velocity);
    ids.par_iter()
        .map(|&i| {
            let b = &bodies[i];
            let rest = mass - b.shape.mass;
            let kinetic = 0.5 * b.shape.mass * (b.velocity - v).norm_squared() * mass / rest;
            let potential: f64 = ids
                .iter()
                .filter(|&&j| j != i)
                .map(|&j| bodies[j].shape.mass / (bodies[j].position - b.position).norm())
                .sum();
            kinetic - g * b.shape.mass * potential
        })
        .collect()
}

/// The clumps of `bodies` (module docs, items 1 and 2): linked by `linking`, refined by mutual boundness with the
/// gravitational constant `g` (m³ kg⁻¹ s⁻²; `None`: no self-gravity, no refinement). Lists of body indices, each
/// ascending, the most massive first (ties by first index).
pub fn bound_clumps(bodies: &[Body], linking: Linking, g: Option<f64>) -> Vec<Vec<usize>> {
    let mut done: Vec<Vec<usize>> = Vec::new();
    let mut todo: Vec<Vec<usize>> = find_clumps(bodies, linking);
    while let Some(set) = todo.pop() {
        let Some(g) = g.filter(|_| set.len() > 1) else {
            done.push(set);
            continue;
        };
        let energy = member_energies(bodies, &set, g);
        let mut unbound: Vec<usize> = (0..set.len()).filter(|&k| energy[k] > 0.0).collect();
        if unbound.is_empty() {
            done.push(set);
            continue;
        }
        // The most unbound quarter first (at least one; ties by index, for determinism).
        unbound.sort_by(|&p, &q| energy[q].total_cmp(&energy[p]).then(p.cmp(&q)));
        unbound.truncate(unbound.len().div_ceil(4));
        let mut is_dropped = vec![false; set.len()];
        for &k in &unbound {
            is_dropped[k] = true;
        }
        let (mut dropped, mut kept) = (Vec::new(), Vec::new());
        for (k, &i) in set.iter().enumerate() {
            if is_dropped[k] { dropped.push(i) } else { kept.push(i) }
        }
        // `set` has ≥ 2 members and at most ⌈n/4⌉ < n are dropped: both parts are strict, non-empty subsets.
        todo.extend(find_clumps_among(bodies, &kept, linking));
        todo.extend(find_clumps_among(bodies, &dropped, linking));
    }
    let mass = |c: &[usize]| c.iter().map(|&i| bodies[i].shape.mass).sum::<f64>();
    done.sort_by(|a, b| mass(b).total_cmp(&mass(a)).then(a[0].cmp(&b[0])));
    done
}

/// Centre of mass, its velocity, the inertia tensor about it and the angular momentum about it of the bodies
/// `members` (module docs, item 3), with `moments(body)` each body's principal moments (kg m²).
fn mass_properties(bodies: &[Body], members: &[usize], moments: &dyn Fn(&Body) -> Vec3) -> (Vec3, Vec3, Mat3, Vec3) {
    let mass: f64 = members.iter().map(|&i| bodies[i].shape.mass).sum();
    let centre = mass_mean(bodies, members, mass, |b| b.position);
    let velocity = mass_mean(bodies, members, mass, |b| b.velocity);
    let (mut inertia, mut l) = (Mat3::zeros(), Vec3::zeros());
    for &i in members {
        let b = &bodies[i];
        // R maps world to body: the body's tensor in the world frame is Rᵀ diag(I) R.
        let r = rotation_matrix(&b.quaternion.normalize());
        let own = r.transpose() * Mat3::from_diagonal(&moments(b)) * r;
        let (d, u) = (b.position - centre, b.velocity - velocity);
        inertia += own + b.shape.mass * (Mat3::identity() * d.norm_squared() - d * d.transpose());
        l += b.shape.mass * d.cross(&u) + own * (r.transpose() * b.spin_body);
    }
    (centre, velocity, inertia, l)
}

/// Spin `ω = I⁻¹ L` (world frame, rad/s) of the bodies `members` as one aggregate about their centre of mass, with
/// `moments(body)` the principal moments of each body (kg m²); zero when the inertia tensor is singular.
pub fn clump_spin(bodies: &[Body], members: &[usize], moments: impl Fn(&Body) -> Vec3) -> Vec3 {
    let (_, _, inertia, l) = mass_properties(bodies, members, &moments);
    inertia.try_inverse().map_or_else(Vec3::zeros, |inv| inv * l)
}

/// `n` with its noun for a printed line: `counted(1, "body", "bodies")` is `1 body`, with 2 `2 bodies`.
pub fn counted(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// Where a clump goes (module docs, item 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Fate {
    /// The largest remnant itself.
    Largest,
    /// Bound to the largest remnant.
    Bound,
    /// Unbound from the largest remnant.
    Escaping,
}

impl Fate {
    /// The lowercase name (`largest`, `bound`, `escaping`).
    pub fn name(self) -> &'static str {
        match self {
            Fate::Largest => "largest",
            Fate::Bound => "bound",
            Fate::Escaping => "escaping",
        }
    }
}

/// One clump (module docs, item 3).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Clump {
    /// Body indices (0-based rows of the snapshot), ascending.
    pub members: Vec<usize>,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Mass over the mass of all bodies.
    pub mass_fraction: f64,
    /// Centre of mass (m, world frame).
    pub centre_m: [f64; 3],
    /// Centre-of-mass velocity (m/s, world frame).
    pub velocity_m_s: [f64; 3],
    /// Spin `ω = I⁻¹ L` (rad/s, world frame).
    pub spin_rad_s: [f64; 3],
    /// Spin period `2π/|ω|` (h); `None` without spin.
    pub period_h: Option<f64>,
    /// Principal moments of the inertia tensor about the centre of mass, ascending (kg m²).
    pub principal_moments_kg_m2: [f64; 3],
    /// `b/a` of the equivalent uniform ellipsoid.
    pub b_over_a: f64,
    /// `c/a` of the equivalent uniform ellipsoid.
    pub c_over_a: f64,
    /// Largest, bound to it, or escaping.
    pub fate: Fate,
}

/// The properties of the clump `members` of `bodies` (total mass of all bodies `total`), fate left to the caller.
fn clump_properties(bodies: &[Body], members: Vec<usize>, total: f64, moments: &dyn Fn(&Body) -> Vec3) -> Clump {
    let mass: f64 = members.iter().map(|&i| bodies[i].shape.mass).sum();
    let (centre, velocity, inertia, l) = mass_properties(bodies, &members, moments);
    let spin = inertia.try_inverse().map_or_else(Vec3::zeros, |inv| inv * l);
    let mut i: Vec<f64> = inertia.symmetric_eigen().eigenvalues.iter().copied().collect();
    i.sort_by(f64::total_cmp);
    let k = 5.0 / (2.0 * mass);
    // Rounding can make the smallest square a hair negative for a flat set.
    let a2 = k * (i[1] + i[2] - i[0]);
    let b2 = (k * (i[0] + i[2] - i[1])).max(0.0);
    let c2 = (k * (i[0] + i[1] - i[2])).max(0.0);
    let rate = spin.norm();
    Clump {
        mass_kg: mass,
        mass_fraction: mass / total,
        centre_m: centre.into(),
        velocity_m_s: velocity.into(),
        spin_rad_s: spin.into(),
        period_h: (rate > 0.0).then(|| 2.0 * std::f64::consts::PI / rate / 3600.0),
        principal_moments_kg_m2: [i[0], i[1], i[2]],
        b_over_a: (b2 / a2).sqrt(),
        c_over_a: (c2 / a2).sqrt(),
        fate: Fate::Escaping,
        members,
    }
}

/// The clumps of one snapshot (`analysis/clumps.csv`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClumpReport {
    /// The linking length as a fraction of the smaller body's smallest semi-axis ([`Linking::SurfaceGap`]).
    pub gap_fraction: f64,
    /// The gravitational constant of the boundness refinement (m³ kg⁻¹ s⁻²); `None`: no self-gravity, none made.
    pub g: Option<f64>,
    /// Mass of all bodies (kg).
    pub total_mass_kg: f64,
    /// The clumps, the most massive first.
    pub clumps: Vec<Clump>,
}

/// A remnant in `analysis.json` (`largest_remnant`, `second_remnant`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RemnantSummary {
    /// Mass over the mass of all bodies.
    pub mass_fraction: f64,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Number of bodies in it.
    pub n_members: usize,
    /// Spin period (h); `None` without spin.
    pub period_h: Option<f64>,
    /// `b/a` of the equivalent uniform ellipsoid.
    pub b_over_a: f64,
    /// `c/a` of the equivalent uniform ellipsoid.
    pub c_over_a: f64,
}

impl From<&Clump> for RemnantSummary {
    fn from(c: &Clump) -> Self {
        RemnantSummary {
            mass_fraction: c.mass_fraction,
            mass_kg: c.mass_kg,
            n_members: c.members.len(),
            period_h: c.period_h,
            b_over_a: c.b_over_a,
            c_over_a: c.c_over_a,
        }
    }
}

/// The clumps of a snapshot in `analysis.json`: the finder's settings, the counts, the two largest remnants.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClumpSummary {
    /// Linking length over the smaller body's smallest semi-axis ([`ClumpReport::gap_fraction`]).
    pub clump_gap_fraction: f64,
    /// G of the boundness refinement (m³ kg⁻¹ s⁻²); `None`: without self-gravity, none made.
    pub clump_g: Option<f64>,
    /// Number of clumps (single bodies included).
    pub n_clumps: usize,
    /// Number of clumps escaping the largest remnant.
    pub n_escaping_clumps: usize,
    /// The most massive clump.
    pub largest_remnant: Option<RemnantSummary>,
    /// The second most massive clump.
    pub second_remnant: Option<RemnantSummary>,
}

/// The clumps of `bodies` (module docs): friends of friends with a surface gap of `gap_fraction` (dimensionless,
/// ≥ 0; [`DEFAULT_GAP_FRACTION`]) of the smaller smallest semi-axis, refined by boundness with `g` (SI; `None`
/// without self-gravity), with `moments(body)` each body's principal moments (kg m²). An empty snapshot has no
/// clumps.
pub fn analyse_clumps(
    bodies: &[Body],
    gap_fraction: f64,
    g: Option<f64>,
    moments: impl Fn(&Body) -> Vec3,
) -> ClumpReport {
    let total: f64 = bodies.iter().map(|b| b.shape.mass).sum();
    let mut clumps: Vec<Clump> = bound_clumps(bodies, Linking::SurfaceGap(gap_fraction), g)
        .into_iter()
        .map(|members| clump_properties(bodies, members, total, &moments))
        .collect();
    if let Some((largest, others)) = clumps.split_first_mut() {
        largest.fate = Fate::Largest;
        let (m0, r0, v0) = (
            largest.mass_kg,
            Vec3::from(largest.centre_m),
            Vec3::from(largest.velocity_m_s),
        );
        for c in others {
            let (m, r, v) = (c.mass_kg, Vec3::from(c.centre_m), Vec3::from(c.velocity_m_s));
            let energy =
                0.5 * m * m0 / (m + m0) * (v - v0).norm_squared() - g.unwrap_or(0.0) * m * m0 / (r - r0).norm();
            c.fate = if energy < 0.0 { Fate::Bound } else { Fate::Escaping };
        }
    }
    ClumpReport {
        gap_fraction,
        g,
        total_mass_kg: total,
        clumps,
    }
}

impl ClumpReport {
    /// The largest remnant, if there is a clump.
    pub fn largest(&self) -> Option<RemnantSummary> {
        self.clumps.first().map(RemnantSummary::from)
    }

    /// The second most massive clump, if there are two.
    pub fn second(&self) -> Option<RemnantSummary> {
        self.clumps.get(1).map(RemnantSummary::from)
    }

    /// The settings, counts and two largest remnants, for `analysis.json`.
    pub fn summary(&self) -> ClumpSummary {
        ClumpSummary {
            clump_gap_fraction: self.gap_fraction,
            clump_g: self.g,
            n_clumps: self.clumps.len(),
            n_escaping_clumps: self.n_escaping(),
            largest_remnant: self.largest(),
            second_remnant: self.second(),
        }
    }

    /// How many clumps escape the largest remnant.
    pub fn n_escaping(&self) -> usize {
        self.clumps.iter().filter(|c| c.fate == Fate::Escaping).count()
    }

    /// One line for the terminal: the largest remnant (mass fraction, bodies, period, axis ratios), the second,
    /// and how many clumps escape.
    pub fn summary_line(&self) -> String {
        let Some(lr) = self.largest() else {
            return "clumps: none (no bodies)".into();
        };
        // a spin left by rounding alone gives an astronomical period: scientific notation keeps it short
        let period = |p: Option<f64>| {
            p.map_or("none".into(), |p| {
                if p < 1e4 {
                    format!("{p:.3} h")
                } else {
                    format!("{p:.3e} h")
                }
            })
        };
        let second = self.second().map_or("none".into(), |s| {
            format!("{:.4} ({})", s.mass_fraction, counted(s.n_members, "body", "bodies"))
        });
        format!(
            "largest remnant: {:.4} of all bodies' mass ({}, {:.4e} kg), spin period {}, b/a {:.3}, c/a {:.3}; \
             second remnant {second}; {}, {} escaping the largest remnant",
            lr.mass_fraction,
            counted(lr.n_members, "body", "bodies"),
            lr.mass_kg,
            period(lr.period_h),
            lr.b_over_a,
            lr.c_over_a,
            counted(self.clumps.len(), "clump", "clumps"),
            self.n_escaping(),
        )
    }

    /// `clumps.csv`: one row per clump, the largest first, units in the column names; `members` lists the body
    /// indices (0-based rows of the snapshot) separated by spaces.
    pub fn csv(&self) -> String {
        let mut text = String::from(
            "rank,n_members,mass_kg,mass_fraction,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,wx_rad_s,wy_rad_s,wz_rad_s,\
             period_h,i1_kg_m2,i2_kg_m2,i3_kg_m2,b_over_a,c_over_a,fate,members\n",
        );
        for (k, c) in self.clumps.iter().enumerate() {
            let nums = |v: &[f64]| v.iter().map(|x| format!("{x:e}")).collect::<Vec<_>>().join(",");
            let members: Vec<String> = c.members.iter().map(usize::to_string).collect();
            text += &format!(
                "{k},{},{:e},{:e},{},{},{},{},{},{:e},{:e},{},{}\n",
                c.members.len(),
                c.mass_kg,
                c.mass_fraction,
                nums(&c.centre_m),
                nums(&c.velocity_m_s),
                nums(&c.spin_rad_s),
                c.period_h.map_or(String::new(), |p| format!("{p:e}")),
                nums(&c.principal_moments_kg_m2),
                c.b_over_a,
                c.c_over_a,
                c.fate.name(),
                members.join(" "),
            );
        }
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ellipsoid::body::Ellipsoid;
    use crate::math::Vec4;

    fn sphere(x: f64, v: f64, mass: f64) -> Body {
        Body {
            shape: Ellipsoid {
                axes: Vec3::new(1.0, 1.0, 1.0),
                mass,
            },
            position: Vec3::new(x, 0.0, 0.0),
            velocity: Vec3::new(v, 0.0, 0.0),
            quaternion: Vec4::new(0.0, 0.0, 0.0, 1.0),
            spin_body: Vec3::zeros(),
        }
    }

    /// The member test is the exact two-body energy for a pair: unit masses touching at r = 2 with G = 1 are bound
    /// below `½ μ v² = G m² / r`, i.e. a relative speed `v = √(2 G M / r) = √2` (escape speed), split above.
    #[test]
    fn a_pair_splits_exactly_at_its_escape_speed() {
        let escape = 2f64.sqrt();
        for (speed, n) in [(0.99 * escape, 1), (1.01 * escape, 2)] {
            let bodies = [sphere(0.0, -0.5 * speed, 1.0), sphere(2.0, 0.5 * speed, 1.0)];
            assert_eq!(
                bound_clumps(&bodies, Linking::SurfaceGap(0.1), Some(1.0)).len(),
                n,
                "v {speed}"
            );
        }
        // without self-gravity nothing is refined
        let fast = [sphere(0.0, -10.0, 1.0), sphere(2.0, 10.0, 1.0)];
        assert_eq!(bound_clumps(&fast, Linking::SurfaceGap(0.1), None).len(), 1);
    }

    /// A body flying off the end of a bound chain is dropped; the rest stays one clump, and the fate of the
    /// dropped one against the largest is escaping.
    #[test]
    fn a_fast_member_leaves_a_chain_and_escapes() {
        let bodies = [
            sphere(0.0, 0.0, 1.0),
            sphere(2.0, 0.0, 1.0),
            sphere(4.0, 0.0, 1.0),
            sphere(6.0, 5.0, 1.0),
        ];
        let report = analyse_clumps(&bodies, 0.1, Some(1.0), |b| b.shape.principal_moments(2.5));
        let members: Vec<&[usize]> = report.clumps.iter().map(|c| c.members.as_slice()).collect();
        assert_eq!(members, vec![&[0, 1, 2][..], &[3]]);
        assert_eq!(report.clumps[1].fate, Fate::Escaping);
        assert_eq!(report.n_escaping(), 1);
    }

    /// A count of one prints with the singular noun: the chain's dropped body is "(1 body)", never "(1 bodies)".
    #[test]
    fn a_count_of_one_prints_a_singular_noun() {
        let bodies = [sphere(0.0, 0.0, 1.0), sphere(2.0, 0.0, 1.0), sphere(6.0, 5.0, 1.0)];
        let line = analyse_clumps(&bodies, 0.1, Some(1.0), |b| b.shape.principal_moments(2.5)).summary_line();
        assert!(line.contains("(2 bodies,") && line.contains("(1 body)"), "{line}");
        assert!(!line.contains("1 bodies") && !line.contains(" 1 clumps"), "{line}");
        let one = analyse_clumps(&bodies[..1], 0.1, Some(1.0), |b| b.shape.principal_moments(2.5)).summary_line();
        assert!(one.contains("(1 body,") && one.contains("; 1 clump,"), "{one}");
    }
}
