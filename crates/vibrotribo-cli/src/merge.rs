//! `vibrotribo merge`: combines the shards of one sweep, map or basins job into the
//! unsharded output, recognising the job by its manifest.

use anyhow::Result;

use crate::job::MergeArgs;

/// Runs `vibrotribo merge`.
pub fn run(args: &MergeArgs) -> Result<()> {
    let first = &args.shards[0];
    if first.join("map.json").exists() {
        crate::map::merge(args)?;
    } else if first.join("basins.json").exists() {
        crate::basins::merge(args)?;
    } else {
        crate::sweep::merge(args)?;
    }
    println!("merged {} shards into {}", args.shards.len(), args.out.display());
    Ok(())
}
