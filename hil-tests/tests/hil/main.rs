//! The HIL tests: the release firmware image in simavr, watched at its pins,
//! its serial ports and its card. One test binary, one module per topic, so
//! that the tests of every topic share the cores (`cargo test -p hil-tests
//! -- MODULE::` runs one topic).

mod arcs;
mod boot;
mod buttons;
mod card;
mod card_faults;
mod card_print;
mod cncjs;
mod coils;
mod drivers;
mod feed;
mod flashing;
mod flow_control;
mod grbl_conformance;
mod grbl_protocol;
mod grbl_system;
mod harness;
mod job;
mod line_ends;
mod machines;
mod motion;
mod plotter_stress;
mod power_cut;
mod print_power_cut;
mod real_files;
mod realtime;
mod scheduler;
mod seed_protocol;
mod senders;
mod settings;
mod settings_cut;
mod sim_cuts;
mod streaming;
mod studio;
mod studio_app;
mod studio_browser;
mod tools;
mod uart1;
