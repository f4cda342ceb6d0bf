//! Granular engines: rubble piles as collections of spheres. [`soft`] is the soft-sphere discrete element
//! method (SSDEM) of Zhang et al. (2017, Icarus 294) ("Zhang17"), with the rotational resistance of their §2.2;
//! [`hard`] the hard-sphere method with predicted collisions of Richardson et al. (2011, Icarus 212). Their scene
//! files share one [`vocabulary`]; [`migrate`] reads and rewrites the old names.

pub mod hard;
pub mod migrate;
pub mod soft;
pub mod vocabulary;

/// Checks the arrays of an engine's `set_particles`: `n` entries each (`what` names them in the message), all finite.
pub(crate) fn check_particle_arrays(
    n: usize,
    what: &str,
    arrays: [(&str, &[crate::math::Vec3]); 3],
) -> Result<(), crate::engine::EngineError> {
    use crate::engine::EngineError;
    for (name, v) in arrays {
        if v.len() != n {
            return Err(EngineError::State(format!(
                "{name}: {} given, the run has {n} {what}",
                v.len()
            )));
        }
        if let Some(i) = v.iter().position(|x| !x.iter().all(|c| c.is_finite())) {
            return Err(EngineError::State(format!("{name}[{i}]: a non-finite value")));
        }
    }
    Ok(())
}

/// The walls' meshes as the run's named surfaces `wall0`, `wall1`, ….
pub(crate) fn wall_surfaces(
    meshes: impl Iterator<Item = crate::geometry::mesh::SurfaceMesh>,
) -> Vec<crate::engine::NamedSurface> {
    meshes
        .enumerate()
        .map(|(k, mesh)| crate::engine::NamedSurface {
            name: format!("wall{k}"),
            mesh,
        })
        .collect()
}
