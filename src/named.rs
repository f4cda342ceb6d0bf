//! Closed sets of named values — an integrator, an engine, a test problem — with the names users type in scene
//! files and on command lines and a line of help for each, so that a program can list and parse them without the
//! library knowing how that program reads its arguments.

/// A closed set of values, each with the name a user types and one line of help.
pub trait Named: Copy + Sized + 'static {
    /// Every value, in the order they are listed to a user.
    const ALL: &'static [Self];
    /// The name a user types (kebab-case, e.g. `"bulirsch-stoer"`).
    fn name(self) -> &'static str;
    /// One line saying what the value is.
    fn help(self) -> &'static str;
    /// The value whose name is `name` (ASCII case ignored); `None` when no value has it.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|v| v.name().eq_ignore_ascii_case(name))
    }
}
