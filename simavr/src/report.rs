//! A run summarised for people and tools: JSON with how it ended, the serial
//! log and per-pin figures.

use crate::elf::ElfInfo;
use crate::outcome::Outcome;
use crate::probe;
use crate::sim::Sim;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub cycles: u64,
    pub sim_seconds: f64,
    pub outcome: Outcome,
    pub watchdog_resets: u32,
    pub peak_stack_bytes: u16,
    pub elf: Option<ElfInfo>,
    pub uart: String,
    /// What USART1 (the second console) sent.
    pub uart1: String,
    pub pins: Vec<PinReport>,
}

#[derive(Clone, Debug, Serialize)]
pub struct PinReport {
    pub name: String,
    pub pin: u8,
    pub edges: usize,
    pub rising: usize,
    pub min_high_us: Option<f64>,
    pub min_period_us: Option<f64>,
    /// For the STEP pin of a pair probed with `probe_step_dir`.
    pub net_steps: Option<i64>,
}

impl Report {
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a report always serialises")
    }
}

impl Sim {
    /// Summary of the simulation so far, which ended as `outcome`.
    pub fn report(&self, outcome: Outcome) -> Report {
        let pins = self
            .probes()
            .iter()
            .map(|p| {
                let pair = self.step_dir.iter().find(|sd| sd.step == p.pin());
                let net_steps = pair.and_then(|sd| {
                    let dir = self.probes().iter().find(|d| d.pin() == sd.dir)?;
                    Some(probe::net_steps(p, dir, sd.dir_high_is_positive))
                });
                PinReport {
                    name: p.name().to_owned(),
                    pin: p.pin(),
                    edges: p.edge_count(),
                    rising: p.rising_count(),
                    min_high_us: p.min_high_us(),
                    min_period_us: p.min_period_us(),
                    net_steps,
                }
            })
            .collect();
        Report {
            cycles: self.cycles(),
            sim_seconds: self.time_s(),
            outcome,
            watchdog_resets: self.watchdog_resets(),
            peak_stack_bytes: self.peak_stack_bytes(),
            elf: self.elf().copied(),
            uart: self.uart_text(),
            uart1: self.uart1_text(),
            pins,
        }
    }
}
