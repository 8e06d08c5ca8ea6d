//! Studies built on the contact model and the line: what a contact costs and how accurate it is
//! (`contact_cost`); later Monte Carlo robustness and accuracy-vs-time.

pub mod contact_cost;
