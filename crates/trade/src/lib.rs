//! The speed/accuracy trade, measured and chosen from.
//!
//! Every frame the toolkit can draw is a [`Setting`] of one [`Family`]: an environment-lit frame
//! (extraction method and K, shadow technique and its knobs, paper 001's split, Weber skipping),
//! a point-lit one (paraboloid or cube maps, their resolution and PCF), or a composite into a
//! photograph (passes, HDR or LDR, the sources' maps). [`measure`], [`measure_point`] and
//! [`measure_composite`] time a setting's frame and take its error against the family's truth;
//! [`Run`] holds the measurements and writes `trade.csv` / `trade.json`; [`front`] marks Pareto
//! fronts and [`choose`] picks the least error within a time budget, one family at a time;
//! [`Shard`] splits a map library over machines and [`merge`] joins the shards' runs;
//! [`report::html`] draws the plots.
//!
//! **Architecture invariant:** shadow techniques are reached only through
//! `gpu::ShadowTechnique`, extraction only through `light_extract::extractor`, compositing only
//! through `differential_composite`'s GPU compositor and its settings: a new technique adds a
//! [`Shadow`] value and its [`TechniqueSpec`] (built by the one [`TechniqueBuilder`], which
//! `validate` and the benches use too), nothing else here changes. Families
//! never share a front or a choice (their errors are against different truths). Library code:
//! no printing, progress goes to a callback.

pub mod args;
pub mod backdrop;
pub mod banding;
pub mod capture;
pub mod composite;
pub mod composite_rows;
pub mod front;
pub mod lights;
pub mod measure;
pub mod offline;
pub mod point;
pub mod report;
pub mod session;
pub mod setting;
pub mod shafts;
pub mod shard;
pub mod stages;
pub mod table;
pub mod techniques;

pub use backdrop::{BackdropSession, BackdropSettings};
pub use banding::{BandingCase, BandingRow, Interleave, measure_banding};
pub use capture::{PhotoSettings, photograph, photograph_with};
pub use composite::{CompositeCase, measure_composite};
pub use front::{ChooseError, Measurement, Point, choose, front as pareto_front, mark_fronts, overall, pareto};
pub use measure::{Case, Passes, Plan, measure};
pub use point::{PointCase, measure_point};
pub use session::{Session, SessionSettings};
pub use setting::{
    CompositeSetting, EQUAL_TEXEL_SIDES, EnvSetting, Family, MapVariant, PatchMaps, PointSetting, Preset, Setting,
    Shadow, equal_texel_variants,
};
pub use shard::{Shard, ShardError};
pub use table::{Run, RunConfig, merge};
pub use techniques::{TechniqueBuilder, TechniqueSpec, traced_visibility};

use std::path::PathBuf;

/// What can go wrong measuring, writing, reading or merging a trade.
#[derive(Debug, thiserror::Error)]
pub enum TradeError {
    /// A file or folder could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A JSON file that is not a run (of the trade or of `eval-lights`).
    #[error("{path}: {message}")]
    Json {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// Shards measured with different configurations cannot merge.
    #[error("{path}: measured differently from {other}: {what}")]
    Mismatch {
        /// The shard's folder.
        path: PathBuf,
        /// The first shard's folder.
        other: PathBuf,
        /// The differing configurations.
        what: String,
    },
    /// The same shard or measurement twice in a merge.
    #[error("{path}: {what} is already in the merge")]
    Duplicate {
        /// The shard's folder.
        path: PathBuf,
        /// What is repeated.
        what: String,
    },
    /// A merge of nothing.
    #[error("nothing to merge: give at least one folder of a run (with its trade.json or eval-lights.json)")]
    NothingToMerge,
    /// An unknown scene.
    #[error("scene: {0}")]
    Scene(String),
    /// An unknown or failing extraction method.
    #[error("extraction method: {0}")]
    Method(String),
    /// GPU failures.
    #[error("GPU: {0}")]
    Gpu(#[from] gpu::GpuError),
    /// A frame that could not be made.
    #[error("render: {0}")]
    Render(String),
    /// A plot that could not be drawn.
    #[error("plot: {0}")]
    Plot(String),
}
