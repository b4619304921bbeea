//! Parameter sweeps over a configuration's keys: the points of a grid, each a
//! [`run_point`](crate::study::run_point) of the configuration with some keys set, run in
//! parallel in chunks and delivered in grid order (so results do not depend on the thread
//! count), or continued from one value to the next; and their results in columns
//! ([`SweepColumns`]). The command line and the Python package both run their sweeps and
//! maps through here.

mod request;
mod runner;
mod table;

pub use request::{PointRequest, PointRequestError};
pub use runner::{
    Continuation, Delivery, PointRunner, SweepError, grid, is_stopped, run_chunks, run_continued, run_grid,
    run_grid_on,
};
pub use table::{
    Cell, Column, IMPACT_COLUMNS, Kind, LYAPUNOV_COLUMNS, MOTION_COLUMNS, PointColumns, SweepColumns, Table,
    error_text, impact_rows, orbit_columns, orbit_rows, point_columns,
};
