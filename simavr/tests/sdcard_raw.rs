//! The firmware's way of reading the card (raw handles, one volume, one
//! directory, one file open at a time), on the host against the model.

use embedded_hal::spi::{Operation, SpiDevice};
use embedded_sdmmc::{Mode, TimeSource, Timestamp, VolumeIdx, VolumeManager};
use std::cell::RefCell;
use std::path::Path;
use std::rc::Rc;
use taut_simavr::sdcard::{SdCard, SdImage};
use taut_simavr::sdimage::FatChoice;

struct Bus(Rc<RefCell<SdCard>>);

impl embedded_hal::spi::ErrorType for Bus {
    type Error = core::convert::Infallible;
}

impl SpiDevice for Bus {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        let mut card = self.0.borrow_mut();
        for op in ops {
            match op {
                Operation::Read(b) => b.iter_mut().for_each(|x| *x = card.exchange(0xFF, true)),
                Operation::Write(b) => b.iter().for_each(|&x| {
                    card.exchange(x, true);
                }),
                Operation::Transfer(r, w) => {
                    for i in 0..r.len().max(w.len()) {
                        let v = card.exchange(*w.get(i).unwrap_or(&0xFF), true);
                        if let Some(x) = r.get_mut(i) {
                            *x = v;
                        }
                    }
                }
                Operation::TransferInPlace(b) => {
                    b.iter_mut().for_each(|x| *x = card.exchange(*x, true))
                }
                Operation::DelayNs(_) => {}
            }
        }
        card.exchange(0xFF, false);
        Ok(())
    }
}

struct NoDelay;
impl embedded_hal::delay::DelayNs for NoDelay {
    fn delay_ns(&mut self, _ns: u32) {}
}

struct Clock;
impl TimeSource for Clock {
    fn get_timestamp(&self) -> Timestamp {
        Timestamp::from_calendar(2025, 1, 1, 0, 0, 0).unwrap()
    }
}

#[test]
fn the_sample_card_reads_with_raw_handles_and_one_of_each() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/card");
    let card = Rc::new(RefCell::new(SdCard::new(
        SdImage::from_dir(&dir, FatChoice::Fat16).unwrap(),
    )));
    let sd = embedded_sdmmc::SdCard::new(Bus(card.clone()), NoDelay);
    assert!(sd.num_bytes().unwrap() > 0);
    let vm: VolumeManager<_, _, 1, 1, 1> = VolumeManager::new_with_limits(sd, Clock, 1);
    let vol = vm.open_raw_volume(VolumeIdx(0)).unwrap();
    let root = vm.open_root_dir(vol).unwrap();
    let file = vm
        .open_file_in_dir(root, "param.txt", Mode::ReadOnly)
        .unwrap();
    let mut buf = [0u8; 64];
    let n = vm.read(file, &mut buf).unwrap();
    assert!(std::str::from_utf8(&buf[..n])
        .unwrap()
        .starts_with("tvar = 6"));
}
