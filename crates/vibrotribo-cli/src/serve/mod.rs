//! `vibrotribo serve`: a local web server with one page (an interactive explorer: parameters,
//! the run view, an orbit diagram, a power map) and a JSON API, on the same engine as the
//! other commands. Every asset is embedded in the binary, so it works offline.
//!
//! The API calls the library functions the commands call (the run layer of `simulate`, the
//! point runner of `sweep` and `map`), so its numbers are theirs.

mod api;
mod assets;
mod branches;
mod cancel;
mod error;
mod grid;
mod memory;
mod request;
mod run_view;
mod schema;
mod server;

pub use server::{ServeArgs, run};
