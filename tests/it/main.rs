//! axcomp integration tests that need only Rust (`cargo test`): the CLI
//! through the binary, the web app over HTTP on the loopback, the library's
//! stages end to end. One binary (see Cargo.toml `autotests = false`). The
//! tests that need LinuxCNC, Chromium or Wine are the `system` target
//! (tests/system/), which `scripts/test` runs too.
//!
//! Real third-party data is read by path from `../shared/data` (never copied
//! into the repository); small inputs and expected outputs live in `tests/data`.

mod architecture;
mod axis_identity;
mod backlash;
mod bad_input;
mod cli;
mod close_loop;
mod conformance;
mod convert;
mod cross_axis;
mod demo;
mod diagnose;
mod diagnose_periodic;
mod diagnose_wire;
mod doc_examples;
mod evaluate_ecmc;
mod fagor;
mod fagor_update;
mod fanuc;
mod fanuc_modes;
mod fanuc_read_note;
mod fanuc_update;
mod fanuc_web;
mod flags;
mod generated_docs;
mod http;
mod injected;
mod inputs;
mod json_reference;
mod links;
mod loadable;
mod model;
mod numbers;
mod outputs;
mod page;
mod parity;
mod pixels;
mod predict;
mod read_api_pos;
mod report;
mod retest_case;
mod rotary;
mod rotary_effects;
mod rotary_units;
mod serve;
mod server;
mod servo;
mod smaller;
mod standards;
mod survey;
mod survey_optics;
mod thermal;
mod thermal_front;
mod thermal_hal;
mod together;
mod units_figures;
mod units_wire;
mod util;
mod verdict;
mod web_existing;
