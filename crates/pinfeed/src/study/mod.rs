//! Studies built on the contact model and the line: what a contact costs and how accurate it is
//! (`contact_cost`), what a set of configuration maps costs (`map_cost`), what accuracy costs in
//! time (`accuracy`), Monte Carlo robustness studies with sharding and merging (`mc`), and line
//! designs side by side on one part stream (`compare`), and fuzzing of every input (`robustness`).

pub mod accuracy;
pub mod bench_error;
pub mod bundled;
pub mod compare;
pub mod contact_cost;
pub mod line_cost;
pub mod map_cost;
pub mod map_tier;
pub mod mc;
pub mod robustness;
