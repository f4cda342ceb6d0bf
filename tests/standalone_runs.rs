//! Runs that stand alone (issue 41): a scene whose input file is given by a relative path, run from its own
//! directory, leaves a run directory that every reader (`check`, `export`, `render`, `analyze`) reads from any
//! other working directory: the run's `scene.toml` copy names the input by its absolute path.

mod common;

use common::{rubblepile, temp_dir};
use std::path::Path;
use std::process::Output;

fn assert_ok(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "{what}: exit {:?}\nstdout: {}\nstderr: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The value of `scene.<key>` in the run's scene copy.
fn copied_input(run: &Path, key: &str) -> String {
    let text = std::fs::read_to_string(run.join("scene.toml")).unwrap();
    let table: toml::Table = text.parse().unwrap();
    table["scene"][key].as_str().unwrap().to_string()
}

/// Two soft spheres inside a spherical wall, their particles in `p.csv` beside the scene.
const SOFT_SCENE: &str = r#"[scene]
kind = "soft-spheres"
t_end = 0.01
seed = 1
particles_file = "p.csv"   # relative to this file
[stepping]
dt = 1e-4
[material]
k_n = 4.2e8
[output]
every = 0.005
[[wall]]
kind = "sphere"
centre = [0.0, 0.0, 0.0]
radius = 5.0
"#;

const SOFT_PARTICLES: &str = "t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz
0,0,1000,0.5,-1,0,0,1,0,0,0,0,0
0,1,1000,0.5,1,0,0,-1,0,0,0,0,0
";

#[test]
fn soft_sphere_run_with_a_relative_particles_file_is_read_from_anywhere() {
    let base = temp_dir("standalone-soft");
    std::fs::create_dir_all(base.join("in")).unwrap();
    std::fs::write(base.join("in/s.toml"), SOFT_SCENE).unwrap();
    std::fs::write(base.join("in/p.csv"), SOFT_PARTICLES).unwrap();
    assert_ok(
        &rubblepile(&base, &["run", "in/s.toml", "--out", "out", "--no-progress"]),
        "run",
    );
    let run = base.join("out");
    let named = copied_input(&run, "particles_file");
    assert!(Path::new(&named).is_absolute(), "{named}");
    assert_eq!(
        std::fs::canonicalize(&named).unwrap(),
        std::fs::canonicalize(base.join("in/p.csv")).unwrap()
    );
    // The comment on the rewritten line stays.
    assert!(
        std::fs::read_to_string(run.join("scene.toml"))
            .unwrap()
            .contains("# relative to this file")
    );

    let elsewhere = temp_dir("standalone-soft-elsewhere");
    let dir = run.to_str().unwrap();
    assert_ok(&rubblepile(&elsewhere, &["check", dir]), "check");
    assert_ok(&rubblepile(&elsewhere, &["export", "vtk", dir]), "export vtk");
    assert!(run.join("vtk/run.pvd").is_file());
    assert_ok(&rubblepile(&elsewhere, &["render", dir, "--size", "64x64"]), "render");
}

/// Semi-axes, position, velocity and quaternion of a fragment.
type Fragment = ([f64; 3], [f64; 3], [f64; 3], [f64; 4]);

#[test]
fn flyby_run_with_a_relative_bodies_file_is_analysed_from_anywhere() {
    let base = temp_dir("standalone-flyby");
    std::fs::create_dir_all(base.join("in")).unwrap();
    // Four fragments of 3000 kg/m³ held by their gravity (tests/flyby.rs's pile), spinning about z.
    let bodies: [Fragment; 4] = [
        (
            [60.0, 45.0, 35.0],
            [-50.0, 0.0, 0.0],
            [0.0, -0.0025, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ),
        (
            [50.0, 40.0, 30.0],
            [52.0, 3.0, 0.0],
            [0.0, 0.0026, 0.0],
            [0.0, 0.0, 0.3826834323650898, 0.9238795325112867],
        ),
        (
            [40.0, 30.0, 25.0],
            [0.0, 70.0, 10.0],
            [-0.0035, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ),
        (
            [35.0, 30.0, 20.0],
            [0.0, -65.0, -8.0],
            [0.0033, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ),
    ];
    let mut csv = String::from("t,id,mass,a,b,c,x,y,z,vx,vy,vz,qa,qb,qc,qd,wx,wy,wz\n");
    for (k, (a, r, v, q)) in bodies.iter().enumerate() {
        let mass = 3000.0 * 4.0 / 3.0 * std::f64::consts::PI * a[0] * a[1] * a[2];
        // A rotation about z leaves a spin about z the same in the body frame.
        csv.push_str(&format!(
            "0,{k},{mass:e},{},{},{},{},{},{},{:e},{:e},{:e},{},{},{},{},0,0,5e-5\n",
            a[0], a[1], a[2], r[0], r[1], r[2], v[0], v[1], v[2], q[0], q[1], q[2], q[3]
        ));
    }
    std::fs::write(base.join("in/pile.csv"), csv).unwrap();
    let scene = r#"[scene]
kind = "ellipsoids"
t_end = 1000.0
bodies_file = 'pile.csv'
[model]
kappa = 10.0
[physics]
gravity = {}
contact = {}
dissipation = { F0 = 1e-3 }
[physics.flyby]
mass = 5.9722e25
radius = 6.371e6
q = 9.5e6
v_inf = 3000.0
t_perigee = 500.0
[integrator]
rtol = 1e-9
atol = 1e-9
[output]
times = [0.0, 500.0, 1000.0]
every = 50.0
"#;
    std::fs::write(base.join("in/flyby.toml"), scene).unwrap();
    assert_ok(
        &rubblepile(&base, &["run", "in/flyby.toml", "--out", "out", "--no-progress"]),
        "run",
    );
    let run = base.join("out");
    assert!(Path::new(&copied_input(&run, "bodies_file")).is_absolute());

    let elsewhere = temp_dir("standalone-flyby-elsewhere");
    let dir = run.to_str().unwrap();
    assert_ok(&rubblepile(&elsewhere, &["check", dir]), "check");
    let analyzed = rubblepile(&elsewhere, &["analyze", dir]);
    assert_ok(&analyzed, "analyze");
    // Read as a flyby run (which needs its bodies), not refused as an impact without impact.json.
    assert!(run.join("analysis/flyby.json").is_file());
    assert_ok(&rubblepile(&elsewhere, &["export", "vtk", dir]), "export vtk");
}
