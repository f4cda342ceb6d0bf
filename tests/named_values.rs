//! The library's closed sets of named values ([`rubblepile::named::Named`]): each reads its own names back, and the
//! integrators' names are the ones scene files use.

use rubblepile::driver::SceneKind;
use rubblepile::impact::problems::{NBodyProblem, WorkPrecisionProblem};
use rubblepile::integrate::Method;
use rubblepile::named::Named;

/// Every name of `T` reads back as its own value, and no two values share a name.
fn names_round_trip<T: Named + PartialEq + std::fmt::Debug>() {
    for &v in T::ALL {
        assert_eq!(T::from_name(v.name()), Some(v), "{}", v.name());
        assert_eq!(T::from_name(&v.name().to_uppercase()), Some(v), "case ignored");
        assert!(!v.help().is_empty());
    }
    let mut names: Vec<_> = T::ALL.iter().map(|v| v.name()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), T::ALL.len(), "a name given twice");
    assert_eq!(T::from_name("no-such-value"), None);
}

#[test]
fn every_named_set_reads_its_own_names_back() {
    names_round_trip::<Method>();
    names_round_trip::<SceneKind>();
    names_round_trip::<WorkPrecisionProblem>();
    names_round_trip::<NBodyProblem>();
}

#[test]
fn integrator_names_are_the_scene_files_names() {
    // The scene file reads `[integrator] method` through serde; both spellings must agree.
    for &m in Method::ALL {
        let parsed: Method = serde_json::from_str(&format!("\"{}\"", m.name())).unwrap();
        assert_eq!(parsed, m);
        assert_eq!(m.to_string(), m.name());
    }
}
