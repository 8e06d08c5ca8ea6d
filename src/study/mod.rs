//! Studies built on the contact model and the line: what a contact costs and how accurate it is
//! (`contact_cost`), what a set of configuration maps costs (`map_cost`), line designs side by side
//! on one part stream (`compare`); later Monte Carlo robustness and accuracy-vs-time.

pub mod accuracy;
pub mod compare;
pub mod contact_cost;
pub mod map_cost;
