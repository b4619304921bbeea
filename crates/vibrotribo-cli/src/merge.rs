//! `vibrotribo merge`: combines the shards of one sweep, map or basins job into the
//! unsharded output, recognising the job by its manifest's `command`.

use anyhow::Result;

use crate::job::MergeArgs;
use crate::manifest::Kind;

/// Runs `vibrotribo merge`.
pub fn run(args: &MergeArgs) -> Result<()> {
    match crate::manifest::shard_kind(&args.shards[0])? {
        Kind::Map => crate::map::merge(args)?,
        Kind::Basins => crate::basins::merge(args)?,
        _ => crate::sweep::merge(args)?,
    }
    println!("merged {} shards into {}", args.shards.len(), args.out.display());
    Ok(())
}
