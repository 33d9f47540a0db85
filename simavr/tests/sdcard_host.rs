//! The virtual card under `embedded-sdmmc` (the firmware's SD driver) on the
//! host, over a simulated SPI bus: images built by `sdimage` are mounted,
//! listed and read back byte for byte, in FAT16 and FAT32, on SDSC and SDHC
//! cards, with CRC on and off; writes land in the image; faults surface.

mod common;

use embedded_hal::spi::{Operation, SpiDevice};
use embedded_sdmmc::embedded_sdmmc_types::sdcard::CardType;
use embedded_sdmmc::sdcard::spi::AcquireOpts;
use embedded_sdmmc::{Mode, TimeSource, Timestamp, VolumeIdx, VolumeManager};
use std::cell::RefCell;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::rc::Rc;
use taut_simavr::sdcard::{CardKind, SdCard, SdConfig, SdImage, BLOCK};
use taut_simavr::sdimage::{self, FatChoice};

/// The card on an SPI bus: chip select low for each transaction, and one
/// deselected byte after it, as a bus idles between transactions.
#[derive(Clone)]
struct Bus(Rc<RefCell<SdCard>>);

impl embedded_hal::spi::ErrorType for Bus {
    type Error = std::convert::Infallible;
}

impl SpiDevice for Bus {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        let mut card = self.0.borrow_mut();
        for op in ops {
            match op {
                Operation::Read(buf) => buf.iter_mut().for_each(|b| *b = card.exchange(0xFF, true)),
                Operation::Write(buf) => buf.iter().for_each(|&b| {
                    card.exchange(b, true);
                }),
                Operation::Transfer(read, write) => {
                    for i in 0..read.len().max(write.len()) {
                        let miso = card.exchange(write.get(i).copied().unwrap_or(0xFF), true);
                        if let Some(r) = read.get_mut(i) {
                            *r = miso;
                        }
                    }
                }
                Operation::TransferInPlace(buf) => {
                    buf.iter_mut().for_each(|b| *b = card.exchange(*b, true))
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

type Volumes = VolumeManager<embedded_sdmmc::SdCard<Bus, NoDelay>, Clock>;

/// A card in its slot, powered up with 80 clocks with chip select high.
fn mount(card: SdCard, use_crc: bool) -> (Rc<RefCell<SdCard>>, Volumes) {
    let card = Rc::new(RefCell::new(card));
    for _ in 0..10 {
        card.borrow_mut().exchange(0xFF, false);
    }
    let options = AcquireOpts {
        use_crc,
        acquire_retries: 50,
    };
    let sd = embedded_sdmmc::SdCard::new_with_options(Bus(card.clone()), NoDelay, options);
    (card, VolumeManager::new(sd, Clock))
}

/// Everything in a directory: (short name, size, is a directory).
fn list<D: embedded_sdmmc::BlockDevice>(
    dir: &embedded_sdmmc::Directory<'_, D, Clock, 4, 4, 1>,
) -> Vec<(String, u32, bool)> {
    let mut out = Vec::new();
    dir.iterate_dir(|e| {
        out.push((e.name.to_string(), e.size, e.attributes.is_directory()));
        ControlFlow::Continue(())
    })
    .unwrap();
    out
}

fn check_card(fat: FatChoice, kind: CardKind, use_crc: bool, ncr: u8) {
    let tag = format!("{fat:?}-{kind:?}-{use_crc}-{ncr}");
    let (dir, files) = common::job_folder(&tag, 700 * 1024 + 123);
    let (image, layout) = sdimage::build_image_with_layout(&dir, fat).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(layout.fat32, fat == FatChoice::Fat32, "{tag}");
    let config = SdConfig {
        kind,
        ncr,
        ..SdConfig::default()
    };
    let (card, volumes) = mount(
        SdCard::with_config(SdImage::from_bytes(image), config),
        use_crc,
    );
    {
        let volume = volumes.open_volume(VolumeIdx(0)).unwrap();
        let root = volume.open_root_dir().unwrap();
        let mut names = list(&root);
        names.retain(|(name, _, _)| name != "TAUT");
        names.sort();
        let want = [
            ("BIG.BIN", files["BIG.BIN"].len() as u32, false),
            ("EMPTY", 0, false),
            ("GCODE", 0, true),
            ("MACHINE.TXT", files["Machine.Txt"].len() as u32, false),
            ("PARAM.TXT", files["param.txt"].len() as u32, false),
            ("PORADI.TXT", files["PORADI.TXT"].len() as u32, false),
        ];
        let want: Vec<_> = want.iter().map(|&(n, s, d)| (n.to_owned(), s, d)).collect();
        assert_eq!(names, want, "{tag}");
        // Opened by any case of their names, as the firmware will.
        let gcode = root.open_dir("gcode").unwrap();
        for (name, bytes) in &files {
            let (parent, leaf) = match name.split_once('/') {
                Some((_, leaf)) => (&gcode, leaf),
                None => (&root, name.as_str()),
            };
            let file = parent
                .open_file_in_dir(leaf.to_lowercase().as_str(), Mode::ReadOnly)
                .unwrap_or_else(|e| panic!("{tag}: {name}: {e:?}"));
            let mut back = Vec::new();
            let mut chunk = [0u8; 700];
            while !file.is_eof() {
                let n = file.read(&mut chunk).unwrap();
                back.extend_from_slice(&chunk[..n]);
            }
            assert!(back == *bytes, "{tag}: {name} differs");
        }
    }
    let card = card.borrow();
    let stats = card.stats();
    let big_blocks = (files["BIG.BIN"].len() / BLOCK) as u64;
    assert!(stats.blocks_read > big_blocks, "{tag}: {stats:?}");
    assert_eq!(stats.cmd(0), 1, "{tag}");
    assert_eq!(stats.cmd(59), u32::from(use_crc), "{tag}");
    assert_eq!(stats.crc_errors, 0, "{tag}");
    // Reading writes nothing but, on FAT32, the FSInfo sector.
    assert!(stats.blocks_written <= u64::from(layout.fat32), "{tag}");
}

#[test]
fn fat16_on_sdsc_with_crc() {
    check_card(FatChoice::Fat16, CardKind::Sdsc, true, 1);
}

#[test]
fn fat32_on_sdhc_with_crc() {
    check_card(FatChoice::Fat32, CardKind::Sdhc, true, 1);
}

#[test]
fn fat16_on_sdhc_without_crc_and_slow_responses() {
    check_card(FatChoice::Fat16, CardKind::Sdhc, false, 8);
}

#[test]
fn fat32_on_sdsc_without_crc() {
    check_card(FatChoice::Fat32, CardKind::Sdsc, false, 3);
}

#[test]
fn card_type_and_size_as_the_driver_sees_them() {
    for (kind, want) in [
        (CardKind::Sdsc, CardType::SD2),
        (CardKind::Sdhc, CardType::SdhcSdxc),
    ] {
        let card = SdCard::with_config(
            SdImage::blank(20_000),
            SdConfig {
                kind,
                ..SdConfig::default()
            },
        );
        let capacity = u64::from(card.capacity_blocks()) * BLOCK as u64;
        let (_, volumes) = mount(card, true);
        let sd = volumes.free().0;
        assert_eq!(sd.num_bytes().unwrap(), capacity);
        assert_eq!(sd.get_card_type(), Some(want));
        assert!(capacity >= 20_000 * BLOCK as u64);
    }
}

/// What `embedded-sdmmc` writes, `fatfs` reads back from the image.
#[test]
fn files_written_by_the_driver_are_in_the_image() {
    let (dir, _) = common::job_folder("write", 700 * 1024 + 123);
    let image = sdimage::build_image(&dir, FatChoice::Fat16).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let log: Vec<u8> = (0..5000u32).flat_map(|i| i.to_le_bytes()).collect();
    let (card, volumes) = mount(SdCard::new(SdImage::from_bytes(image)), true);
    {
        let volume = volumes.open_volume(VolumeIdx(0)).unwrap();
        let root = volume.open_root_dir().unwrap();
        let file = root
            .open_file_in_dir("RUN.LOG", Mode::ReadWriteCreateOrTruncate)
            .unwrap();
        file.write(&log).unwrap();
        file.close().unwrap();
    }
    drop(volumes);
    let card = Rc::try_unwrap(card).ok().unwrap().into_inner();
    assert!(card.stats().blocks_written >= (log.len() / BLOCK) as u64);
    assert_eq!(card.stats().crc_errors, 0);
    let back = read_with_fatfs(card.image().bytes(), "RUN.LOG");
    assert!(back == log, "RUN.LOG differs");
}

fn read_with_fatfs(image: &[u8], name: &str) -> Vec<u8> {
    use std::io::Read;
    let start = u32::from_le_bytes(image[0x1C6..0x1CA].try_into().unwrap()) as usize * BLOCK;
    let part = std::io::Cursor::new(image[start..].to_vec());
    let fs = fatfs::FileSystem::new(part, fatfs::FsOptions::new()).unwrap();
    let mut out = Vec::new();
    fs.root_dir()
        .open_file(name)
        .unwrap()
        .read_to_end(&mut out)
        .unwrap();
    out
}

/// A card with job files whose first data block of BIG.BIN is known.
fn faulty_setup(tag: &str) -> (Rc<RefCell<SdCard>>, Volumes, u32) {
    let (dir, files) = common::job_folder(tag, 700 * 1024 + 123);
    let image = sdimage::build_image(&dir, FatChoice::Fat16).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let big = &files["BIG.BIN"];
    let block = image
        .chunks(BLOCK)
        .position(|b| b == &big[..BLOCK])
        .expect("BIG.BIN in the image") as u32;
    let (card, volumes) = mount(SdCard::new(SdImage::from_bytes(image)), true);
    (card, volumes, block)
}

fn read_big(volumes: &Volumes) -> Result<usize, String> {
    let volume = volumes
        .open_volume(VolumeIdx(0))
        .map_err(|e| format!("{e:?}"))?;
    let root = volume.open_root_dir().map_err(|e| format!("{e:?}"))?;
    let file = root
        .open_file_in_dir("BIG.BIN", Mode::ReadOnly)
        .map_err(|e| format!("{e:?}"))?;
    let mut total = 0;
    let mut chunk = [0u8; 512];
    while !file.is_eof() {
        total += file.read(&mut chunk).map_err(|e| format!("{e:?}"))?;
    }
    Ok(total)
}

#[test]
fn a_failing_block_is_a_read_error_and_the_rest_still_reads() {
    let (card, volumes, block) = faulty_setup("fail");
    card.borrow_mut().fail_read(block);
    let err = read_big(&volumes).unwrap_err();
    assert!(err.contains("ReadError"), "{err}");
    card.borrow_mut().clear_faults();
    assert_eq!(read_big(&volumes), Ok(700 * 1024 + 123));
}

#[test]
fn a_corrupt_crc_is_caught_by_the_driver() {
    let (card, volumes, _) = faulty_setup("crc");
    // Mount first, so the corrupt block is file data.
    let _ = volumes.open_volume(VolumeIdx(0)).unwrap();
    card.borrow_mut().corrupt_crc_next();
    let err = read_big(&volumes).unwrap_err();
    assert!(err.contains("CrcError"), "{err}");
}

#[test]
fn a_silent_card_times_out() {
    let (card, volumes, _) = faulty_setup("timeout");
    // Initialised first: a timeout during initialisation is retried.
    assert!(read_big(&volumes).is_ok());
    card.borrow_mut().timeout_next(1);
    let err = read_big(&volumes).unwrap_err();
    assert!(err.contains("Timeout"), "{err}");
}

#[test]
fn a_card_pulled_mid_read_fails_until_reinserted() {
    let (card, volumes, _) = faulty_setup("pull");
    card.borrow_mut().remove_during_transfer();
    assert!(read_big(&volumes).is_err());
    assert!(card.borrow().is_pulled());
    let image = card.borrow().image().clone();
    *card.borrow_mut() = SdCard::new(image);
    volumes.device(|sd| sd.mark_card_uninit());
    assert_eq!(read_big(&volumes), Ok(700 * 1024 + 123));
}

#[test]
fn image_written_to_a_file_is_the_same_card() {
    let (dir, files) = common::job_folder("file", 700 * 1024 + 123);
    let image = SdImage::from_dir(&dir, FatChoice::Auto).unwrap();
    let path = dir.with_extension("img");
    image.save(&path).unwrap();
    let again = SdImage::from_path(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(again == image);
    assert_eq!(
        read_with_fatfs(again.bytes(), "PORADI.TXT"),
        files["PORADI.TXT"]
    );
}

/// The firmware's way of reading the card (raw handles; one volume, one
/// directory and one file open at a time) on the sample card in
/// `examples/card`.
#[test]
fn the_sample_card_reads_with_raw_handles_and_one_of_each() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/card");
    let card = Rc::new(RefCell::new(SdCard::new(
        SdImage::from_dir(&dir, FatChoice::Fat16).unwrap(),
    )));
    let sd = embedded_sdmmc::SdCard::new(Bus(card), NoDelay);
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
