//! The machinery every grid job (sweep, map, basins, attractors) shares: its options
//! (shards, settling, threads), running its points in parallel chunks, and its output
//! directory (manifest, resume, merge of shards).

mod args;
mod files;
mod grid;
mod run;

pub use args::{MergeArgs, RunArgs, Shard, check_recorded};
pub use files::{header_len, point_columns};
pub use grid::{CHECKPOINT, CsvSpec, GridOutput, Layout, merge, read_checkpoint};
pub use run::{
    check_all, check_distinct, estimate_point_memory, estimate_point_output, run_chunked, run_points,
    set_threads,
};
