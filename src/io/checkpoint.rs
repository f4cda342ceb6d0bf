//! Names of the checkpoint files in a run directory. The checkpoint itself (an envelope written by the run driver
//! around the engine's state) is described in `driver`; its bit-exact floats in [`crate::bits`].

/// Name of the checkpoint file in a run directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.json";
/// Name of the temporary file a checkpoint is written to before the rename.
pub const CHECKPOINT_TMP_FILE: &str = "checkpoint.json.tmp";
