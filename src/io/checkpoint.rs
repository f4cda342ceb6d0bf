//! Names of the checkpoint files in a run directory. The checkpoint itself (an envelope written by the run driver
//! around the engine's state) is described in `driver`; its bit-exact floats in [`crate::bits`].

/// Name of the checkpoint file in a run directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.json";
/// Name of the temporary file a checkpoint was written to before the rename by older builds (now a
/// [`crate::io::safe_write`] temporary); `resume` still removes one left behind.
pub const CHECKPOINT_TMP_FILE: &str = "checkpoint.json.tmp";
