//! Run-time diagnostics of a spin-up run (Zhang17 §3, Fig. 5), one row of `spinup.csv` per output sample: spin
//! period, b/a, c/a (§3.1), interior packing fraction η_B (§3.2, Eqs. 13–14), coordination numbers, the fractions
//! with 0 and 1 contacts, and RVE stresses (§3.3.1, Eqs. 15–16) reduced to s_max, p_max, θ_max (Eqs. 20–21).
//!
//! η_B (interior particles only, as in the paper): Voronoi cells ([`crate::geometry::voronoi`]) start as cubes of
//! half-side twice the largest diameter; a cell reaching the inscribed sphere ([`VoronoiCell::reaches`]) is open and
//! excluded, as is every particle within 10 % of the radii sum of an open one (the gapped second layer) and every
//! particle outside the central body. [`InteriorRule::Layers`]: `Σ V_sphere / Σ V_cell` (volume-weighted Eq. 14);
//! [`InteriorRule::Depth`] weights cells by depth below the surface layer, so η_B is continuous in the positions.
//! RVEs: median cuts of the longest extent until each holds 2/3–4/3 of `rve_particles`; Eq. 16's volume sums cell
//! volumes, `(4/3)π r³/η_B` for open cells; wall contacts are left out. `coordination_loaded` counts contacts above
//! [`CONTACT_FORCE_FLOOR`] × the mean normal force (grazing contacts flicker; the creep test judges this one).
//! `s_max = max (σ₁ − σ₃)/2`, `p_max = max −(σ₁ + σ₂ + σ₃)/3` (Pa, positive), `θ_max` in degrees.

use std::path::Path;

use crate::geometry::neighbours::sphere_pairs;
use crate::geometry::shape_metrics::axis_lengths;
use crate::geometry::voronoi::{VoronoiCell, packing_fraction, radical_cells, weighted_packing_fraction};
use crate::granular::soft::forces::{ContactRecord, SoftSystem};
use crate::granular::soft::spinup::{InteriorRule, SpinupDriver, body_rotation, central_body};
use crate::granular::soft::stress::{StressState, particle_stress, rve_stress, stress_state};
use crate::math::{Mat3, Vec3};

/// The `spinup.csv` header.
pub const SPINUP_HEADER: &str = "t,path_period_h,period_h,forcing,body_particles,body_mass_fraction,a,b,c,b_over_a,c_over_a,packing_fraction,interior_particles,coordination_number,fraction_0_contacts,fraction_1_contact,rves,s_max,p_max,theta_max_deg,coordination_loaded\n";

/// The header of `spinup.csv` files written before 27 Nov 2026 (no `coordination_loaded`): still read, with
/// `coordination_loaded` NaN, and a run started with it is resumed in it.
pub const SPINUP_HEADER_LEGACY: &str = "t,path_period_h,period_h,forcing,body_particles,body_mass_fraction,a,b,c,b_over_a,c_over_a,packing_fraction,interior_particles,coordination_number,fraction_0_contacts,fraction_1_contact,rves,s_max,p_max,theta_max_deg\n";

/// The force floor of "in contact" for `coordination_loaded`, as a fraction of the mean normal force of all
/// sphere–sphere contacts of the force evaluation (dimensionless): contacts carrying less are not counted.
pub const CONTACT_FORCE_FLOOR: f64 = 1e-2;

/// One row of `spinup.csv`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SpinupSample {
    /// Time (s).
    pub t: f64,
    /// The path's period at `t` (h).
    pub path_period_h: f64,
    /// The central body's spin period `2π I/L` (h).
    pub period_h: f64,
    /// Whether the forcing is still on.
    pub forcing: bool,
    /// Particles in the central body.
    pub body_particles: usize,
    /// Mass fraction of the central body.
    pub body_mass_fraction: f64,
    /// Semi-axes a ≥ b ≥ c of all particles (m), maximum extents along the principal axes of inertia.
    pub a: f64,
    /// See `a`.
    pub b: f64,
    /// See `a`.
    pub c: f64,
    /// b/a.
    pub b_over_a: f64,
    /// c/a.
    pub c_over_a: f64,
    /// Interior packing fraction η_B (NaN without interior particles).
    pub packing_fraction: f64,
    /// Particles counted in η_B.
    pub interior_particles: usize,
    /// Mean contacts per particle (all particles).
    pub coordination_number: f64,
    /// Fraction of particles without contacts.
    pub fraction_0_contacts: f64,
    /// Fraction of particles with exactly one contact.
    pub fraction_1_contact: f64,
    /// RVEs.
    pub rves: usize,
    /// Largest deviatoric stress over the RVEs (Pa).
    pub s_max: f64,
    /// Largest compressive pressure over the RVEs (Pa, positive).
    pub p_max: f64,
    /// Largest mobilized friction angle over the RVEs (degrees; NaN if none is defined).
    pub theta_max_deg: f64,
    /// Mean contacts per particle (all particles) counting only contacts that carry at least
    /// [`CONTACT_FORCE_FLOOR`] of the mean normal force; NaN when read from a file without it.
    pub coordination_loaded: f64,
}

impl SpinupSample {
    /// The CSV row (with newline), in the columns of [`SPINUP_HEADER`].
    pub fn csv_row(&self) -> String {
        let mut row = self.csv_row_legacy();
        row.pop();
        row.push_str(&format!(",{}\n", self.coordination_loaded));
        row
    }

    /// The CSV row (with newline) in the columns of [`SPINUP_HEADER_LEGACY`], for resuming a run started with it.
    pub fn csv_row_legacy(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            self.t,
            self.path_period_h,
            self.period_h,
            u8::from(self.forcing),
            self.body_particles,
            self.body_mass_fraction,
            self.a,
            self.b,
            self.c,
            self.b_over_a,
            self.c_over_a,
            self.packing_fraction,
            self.interior_particles,
            self.coordination_number,
            self.fraction_0_contacts,
            self.fraction_1_contact,
            self.rves,
            self.s_max,
            self.p_max,
            self.theta_max_deg
        )
    }
}

/// Reads a `spinup.csv` (header [`SPINUP_HEADER`], 21 numbers a row, or [`SPINUP_HEADER_LEGACY`], 20); errors
/// name the file, line and column.
pub fn read_spinup_csv(path: &Path) -> Result<Vec<SpinupSample>, crate::io::table::TableError> {
    use crate::io::table::{Cells, TableError, read_table};
    let table = read_table(path, Cells::Strict)?;
    let header = table.columns.join(",");
    if header != SPINUP_HEADER.trim() && header != SPINUP_HEADER_LEGACY.trim() {
        return Err(TableError::Header {
            path: path.to_path_buf(),
            expected: SPINUP_HEADER.trim().to_string(),
        });
    }
    let mut out = Vec::with_capacity(table.rows.len());
    for v in &table.rows {
        out.push(SpinupSample {
            t: v[0],
            path_period_h: v[1],
            period_h: v[2],
            forcing: v[3] != 0.0,
            body_particles: v[4] as usize,
            body_mass_fraction: v[5],
            a: v[6],
            b: v[7],
            c: v[8],
            b_over_a: v[9],
            c_over_a: v[10],
            packing_fraction: v[11],
            interior_particles: v[12] as usize,
            coordination_number: v[13],
            fraction_0_contacts: v[14],
            fraction_1_contact: v[15],
            rves: v[16] as usize,
            s_max: v[17],
            p_max: v[18],
            theta_max_deg: v[19],
            coordination_loaded: v.get(20).copied().unwrap_or(f64::NAN),
        });
    }
    Ok(out)
}

/// RVEs of the points `members` (indices into `centres`): a binary median-split tree, cutting a set larger than
/// `4/3 × target` across its longest extent. Deterministic (ties broken by index).
pub fn rves(centres: &[Vec3], members: &[usize], target: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut stack = vec![members.to_vec()];
    let limit = (target * 4).div_ceil(3).max(1);
    while let Some(mut set) = stack.pop() {
        if set.len() <= limit {
            if !set.is_empty() {
                out.push(set);
            }
            continue;
        }
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for &i in &set {
            lo = lo.inf(&centres[i]);
            hi = hi.sup(&centres[i]);
        }
        let axis = (hi - lo).imax();
        set.sort_by(|&i, &j| centres[i][axis].total_cmp(&centres[j][axis]).then(i.cmp(&j)));
        let right = set.split_off(set.len() / 2);
        stack.push(right);
        stack.push(set);
    }
    out
}

/// The stress of one RVE.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RveStress {
    /// Mass-less centroid of its particle centres (m).
    pub centre: Vec3,
    /// Particles.
    pub particles: usize,
    /// Principal stresses and Mohr–Coulomb measures of the average stress tensor (Eq. 16).
    pub state: StressState,
}

/// Eq. 15 per particle and Eq. 16 per RVE from the pair contact `records` of the last force evaluation.
/// `volumes[i]` is particle `i`'s volume (m³); `members` the particles to divide into RVEs of about `target`.
pub fn rve_stresses(
    sys: &SoftSystem,
    records: &[ContactRecord],
    volumes: &[f64],
    members: &[usize],
    target: usize,
) -> Vec<RveStress> {
    let ps = &sys.particles;
    let n = ps.len();
    let mut contacts: Vec<Vec<(Vec3, Vec3)>> = vec![Vec::new(); n];
    for r in records.iter().filter(|r| r.j < n) {
        let d = ps[r.j].position - ps[r.i].position;
        let dist = d.norm();
        if dist <= 0.0 {
            continue;
        }
        let nrm = d / dist;
        let f = r.output.force_i;
        contacts[r.i].push((nrm * (ps[r.i].radius - 0.5 * r.overlap), f));
        contacts[r.j].push((-nrm * (ps[r.j].radius - 0.5 * r.overlap), -f));
    }
    let centres: Vec<Vec3> = ps.iter().map(|p| p.position).collect();
    rves(&centres, members, target)
        .into_iter()
        .map(|set| {
            let parts: Vec<(f64, Mat3)> = set
                .iter()
                .map(|&i| (volumes[i], particle_stress(volumes[i], &contacts[i])))
                .collect();
            RveStress {
                centre: set.iter().map(|&i| centres[i]).sum::<Vec3>() / set.len() as f64,
                particles: set.len(),
                state: stress_state(&rve_stress(&parts)),
            }
        })
        .collect()
}

/// Weights of the particles in η_B by [`InteriorRule::Depth`]: a cell is open when it reaches `open_radius`
/// (m, at most the starting cube's half-side: [`VoronoiCell::reaches`], a test that does not turn with the
/// cube); members with closed cells are weighted by their centre's distance `d` (m) to the nearest centre with
/// an open cell, `clamp((d − depth)/ramp, 0, 1)`. O(N × open).
///
/// The rotation-free test matters: with the cube's own faces as the test, a few surface cells of a spinning
/// PP1 closed and opened as the body turned through the cube's 90° symmetry, and a large surface sphere whose
/// cell closed dropped η_B by 0.005 for one sample every quarter turn.
pub fn depth_weights(
    centres: &[Vec3],
    cells: &[VoronoiCell],
    member: &[bool],
    open_radius: f64,
    depth: f64,
    ramp: f64,
) -> Vec<f64> {
    let open: Vec<Vec3> = centres
        .iter()
        .zip(cells)
        .filter(|(_, c)| c.reaches(open_radius))
        .map(|(x, _)| *x)
        .collect();
    centres
        .iter()
        .zip(cells)
        .zip(member)
        .map(|((x, c), &m)| {
            if !m || c.reaches(open_radius) {
                return 0.0;
            }
            let d2 = open
                .iter()
                .map(|o| (o - x).norm_squared())
                .fold(f64::INFINITY, f64::min);
            ((d2.sqrt() - depth) / ramp).clamp(0.0, 1.0)
        })
        .collect()
}

/// Contacts per particle from a force evaluation's contact list: `records` holds each touching pair once (and each
/// sphere–wall contact once, with the wall's `j ≥ n`), so a pair adds one contact to both spheres and a wall
/// contact one to its sphere. `n` is the number of spheres.
pub fn contact_counts<'a>(records: impl IntoIterator<Item = &'a ContactRecord>, n: usize) -> Vec<u32> {
    let mut count = vec![0u32; n];
    for r in records {
        count[r.i] += 1;
        if r.j < n {
            count[r.j] += 1;
        }
    }
    count
}

/// [`contact_counts`] of the contacts whose normal force is at least `floor` times the mean normal force of the
/// sphere–sphere contacts in `records` (wall contacts are counted by the same floor but do not enter the mean).
///
/// ```
/// use rubblepile::granular::soft::contact::Output;
/// use rubblepile::granular::soft::forces::ContactRecord;
/// use rubblepile::granular::soft::spinup_diagnostics::loaded_contact_counts;
/// let rec = |i, j, f| ContactRecord { i, j, overlap: 1e-3, output: Output { normal_force: f, ..Default::default() } };
/// // mean force 100.5 N: the 1 N contact is under 1 % of it and is not counted
/// let counts = loaded_contact_counts(&[rec(0, 1, 200.0), rec(1, 2, 1.0)], 3, 1e-2);
/// assert_eq!(counts, vec![1, 1, 0]);
/// ```
pub fn loaded_contact_counts(records: &[ContactRecord], n: usize, floor: f64) -> Vec<u32> {
    let pairs = records.iter().filter(|r| r.j < n);
    let (sum, k) = pairs.fold((0.0, 0usize), |(s, k), r| (s + r.output.normal_force, k + 1));
    let threshold = if k > 0 { floor * sum / k as f64 } else { 0.0 };
    contact_counts(records.iter().filter(|r| r.output.normal_force >= threshold), n)
}

/// The coordination number of Zhang17 §4.1.1 (Fig. 5, bottom frame; the creep test of §3.3.3): the mean number
/// of contacts per particle over all spheres, from [`contact_counts`] (0 for no spheres).
pub fn mean_coordination(counts: &[u32]) -> f64 {
    counts.iter().map(|&c| c as f64).sum::<f64>() / counts.len().max(1) as f64
}

/// The `spinup.csv` row of the system at time `t` (s). Needs the contact records of the last force evaluation
/// (`sys.keep_records` on for it); `axis` is the spin axis, `path_period` the path's period (s), `interior` the
/// rule for η_B's particles.
pub fn diagnose(
    sys: &SoftSystem,
    axis: &Vec3,
    path_period: f64,
    forcing: bool,
    rve_target: usize,
    interior: InteriorRule,
    t: f64,
) -> SpinupSample {
    let ps = &sys.particles;
    let n = ps.len();
    let member = central_body(ps, sys.touching_pairs());
    let rot = body_rotation(ps, &member, axis);
    let total_mass: f64 = ps.iter().map(|p| p.mass).sum();
    let centres: Vec<Vec3> = ps.iter().map(|p| p.position).collect();
    let masses: Vec<f64> = ps.iter().map(|p| p.mass).collect();
    let radii: Vec<f64> = ps.iter().map(|p| p.radius).collect();
    let ax = axis_lengths(&centres, &masses, &radii);
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    // the starting cube's half-side; a cell is open when it reaches the sphere inscribed in the cube, a test
    // that does not turn with the cube (VoronoiCell::reaches)
    let open_radius = 4.0 * r_max;
    let cells = radical_cells(&centres, &radii, open_radius);
    let (packing, interior) = match interior {
        InteriorRule::Layers => {
            let open: Vec<bool> = cells.iter().map(|c| c.reaches(open_radius)).collect();
            let mut inner: Vec<bool> = member.iter().zip(&open).map(|(m, o)| *m && !o).collect();
            let reach: Vec<f64> = radii.iter().map(|r| 1.1 * r).collect();
            for (i, j) in sphere_pairs(&centres, &reach) {
                if open[i] {
                    inner[j] = false;
                }
                if open[j] {
                    inner[i] = false;
                }
            }
            (
                packing_fraction(&cells, &radii, &inner),
                inner.iter().filter(|&&k| k).count(),
            )
        }
        InteriorRule::Depth { depth, ramp } => {
            let w = depth_weights(&centres, &cells, &member, open_radius, depth, ramp);
            // the count reported is the weights' sum, rounded: the effective number of interior particles
            (
                weighted_packing_fraction(&cells, &radii, &w),
                w.iter().sum::<f64>().round() as usize,
            )
        }
    };
    let eta = packing.unwrap_or(0.64);
    let volumes: Vec<f64> = cells
        .iter()
        .zip(&radii)
        .map(|(c, r)| {
            if c.reaches(open_radius) {
                4.0 / 3.0 * std::f64::consts::PI * r.powi(3) / eta
            } else {
                c.volume
            }
        })
        .collect();
    let count = contact_counts(&sys.records, n);
    let frac = |k: u32| count.iter().filter(|&&c| c == k).count() as f64 / n.max(1) as f64;
    let members: Vec<usize> = (0..n).filter(|&i| member[i]).collect();
    let stresses = rve_stresses(sys, &sys.records, &volumes, &members, rve_target);
    let s_max = stresses.iter().map(|r| r.state.deviatoric).fold(0.0, f64::max);
    let p_max = stresses.iter().map(|r| -r.state.pressure).fold(0.0, f64::max);
    let theta_max = stresses
        .iter()
        .filter_map(|r| r.state.friction_angle_deg)
        .fold(f64::NAN, f64::max);
    SpinupSample {
        t,
        path_period_h: path_period / 3600.0,
        period_h: rot.period() / 3600.0,
        forcing,
        body_particles: members.len(),
        body_mass_fraction: if total_mass > 0.0 { rot.mass / total_mass } else { 0.0 },
        a: ax.a,
        b: ax.b,
        c: ax.c,
        b_over_a: ax.b_over_a(),
        c_over_a: ax.c_over_a(),
        packing_fraction: packing.unwrap_or(f64::NAN),
        interior_particles: interior,
        coordination_number: mean_coordination(&count),
        fraction_0_contacts: frac(0),
        fraction_1_contact: frac(1),
        rves: stresses.len(),
        s_max,
        p_max,
        theta_max_deg: theta_max,
        coordination_loaded: mean_coordination(&loaded_contact_counts(&sys.records, n, CONTACT_FORCE_FLOOR)),
    }
}

/// [`diagnose`] for a run with a spin-up driver at time `t` (s).
pub fn diagnose_run(sys: &SoftSystem, driver: &SpinupDriver, t: f64) -> SpinupSample {
    let s = &driver.settings;
    diagnose(
        sys,
        &s.axis,
        s.path.period(t),
        !driver.released,
        s.rve_particles,
        s.interior,
        t,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(coordination_loaded: f64) -> SpinupSample {
        SpinupSample {
            t: 100.0,
            path_period_h: 3.0,
            period_h: 3.01,
            forcing: true,
            body_particles: 10,
            body_mass_fraction: 1.0,
            a: 3.0,
            b: 2.0,
            c: 1.0,
            b_over_a: 2.0 / 3.0,
            c_over_a: 1.0 / 3.0,
            packing_fraction: 0.64,
            interior_particles: 4,
            coordination_number: 5.5,
            fraction_0_contacts: 0.1,
            fraction_1_contact: 0.0,
            rves: 1,
            s_max: 10.0,
            p_max: 20.0,
            theta_max_deg: 30.0,
            coordination_loaded,
        }
    }

    #[test]
    fn spinup_csv_reads_back_its_rows_and_the_legacy_columns_with_no_loaded_coordination() {
        let dir = std::env::temp_dir().join(format!("rubblepile-spinup-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (new, old) = (dir.join("new.csv"), dir.join("old.csv"));
        std::fs::write(&new, format!("{SPINUP_HEADER}{}", sample(5.25).csv_row())).unwrap();
        std::fs::write(&old, format!("{SPINUP_HEADER_LEGACY}{}", sample(5.25).csv_row_legacy())).unwrap();
        assert_eq!(read_spinup_csv(&new).unwrap(), vec![sample(5.25)]);
        let legacy = read_spinup_csv(&old).unwrap();
        assert!(legacy[0].coordination_loaded.is_nan());
        assert_eq!(
            SpinupSample {
                coordination_loaded: 5.25,
                ..legacy[0]
            },
            sample(5.25)
        );
        // a legacy header over new rows (a run resumed in the wrong columns) is refused
        std::fs::write(&old, format!("{SPINUP_HEADER_LEGACY}{}", sample(5.25).csv_row())).unwrap();
        assert!(read_spinup_csv(&old).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn force_floor_drops_grazing_contacts_and_walls_take_the_same_floor() {
        use crate::granular::soft::contact::Output;
        let rec = |i, j, f| ContactRecord {
            i,
            j,
            overlap: 1e-3,
            output: Output {
                normal_force: f,
                ..Default::default()
            },
        };
        // pair forces 300, 100, 2 N: mean 134 N, floor 1.34 N keeps 2 N; at floor 0.02 (2.68 N) it goes.
        // the wall contact (j = 4 >= n) of 1 N is under both floors and does not enter the mean.
        let records = [rec(0, 1, 300.0), rec(1, 2, 100.0), rec(2, 3, 2.0), rec(3, 4, 1.0)];
        assert_eq!(contact_counts(&records, 4), vec![1, 2, 2, 2]);
        assert_eq!(loaded_contact_counts(&records, 4, 1e-2), vec![1, 2, 2, 1]);
        assert_eq!(loaded_contact_counts(&records, 4, 2e-2), vec![1, 2, 1, 0]);
        assert_eq!(mean_coordination(&loaded_contact_counts(&records, 4, 2e-2)), 1.0);
    }

    #[test]
    fn rve_tree_gives_similar_sizes_covering_every_member_once() {
        let centres = crate::geometry::lattice::hcp_centres(1.0, 30.0);
        let members: Vec<usize> = (0..centres.len()).collect();
        let sets = rves(&centres, &members, 300);
        let mut seen = vec![0; centres.len()];
        for s in &sets {
            assert!(s.len() >= 200 && s.len() <= 400, "RVE of {}", s.len());
            for &i in s {
                seen[i] += 1;
            }
        }
        assert!(seen.iter().all(|&k| k == 1));
        assert!(sets.len() > 5);
    }
}
