//! Command-line values from the library's closed sets ([`rubblepile::named::Named`]): an integrator, an engine, a
//! test problem, listed with their help in `--help` and parsed by name.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use rubblepile::named::Named;

/// The parser of a flag that takes one value of `T` by its name (`--method dop853`).
pub fn choice<T: Named + Send + Sync>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(T::ALL.iter().map(|v| PossibleValue::new(v.name()).help(v.help())))
        // The possible-values parser lets through only the names listed above, so every one reads back.
        .try_map(|name: String| T::from_name(&name).ok_or(name))
}
