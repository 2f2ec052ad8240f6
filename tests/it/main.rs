//! axcomp integration tests: one binary (see Cargo.toml `autotests = false`).
//!
//! Real third-party data is read by path from `../shared/data` (never copied
//! into the repository); small inputs and expected outputs live in `tests/data`.

mod architecture;
mod axis_identity;
mod backlash;
mod bad_input;
mod browser;
mod cli;
mod close_loop;
mod conformance;
mod convert;
mod cross_axis;
mod demo;
mod diagnose;
mod diagnose_periodic;
mod evaluate_ecmc;
mod fagor;
mod flags;
mod http;
mod injected;
mod linuxcnc;
mod model;
mod outputs;
mod predict;
mod read_api_pos;
mod report;
mod rotary;
mod serve;
mod servo;
mod standards;
mod survey;
mod thermal;
mod together;
mod util;
mod verdict;
mod windows;
