//! `taut-sdimage DIR -o card.img [--fat16|--fat32]`: a microSD card image of
//! a folder's files, for the virtual card and for real cards alike.
//! `cargo xtask sdimage` calls it.

use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use taut_simavr::sdimage::{self, FatChoice};

const USAGE: &str = "\
usage: taut-sdimage DIR -o IMAGE [--fat16|--fat32]
  Builds a card image of DIR's files and subfolders: an MBR with one FAT
  partition starting at 1 MiB. FAT16 while the files fit in 64 MiB, FAT32
  beyond or with --fat32. Names are stored as 8.3 short names (longer
  names also get a long-name entry).

  The image is a whole card: write it to a real microSD card with
    sudo dd if=IMAGE of=/dev/sdX bs=1M conv=fsync
  (/dev/sdX is the card itself, not a partition such as /dev/sdX1; check
  with lsblk first: dd overwrites the device without asking).";

struct Args {
    dir: PathBuf,
    out: PathBuf,
    fat: FatChoice,
}

fn parse(args: impl Iterator<Item = String>) -> Result<Args, String> {
    let (mut dir, mut out, mut fat) = (None, None, FatChoice::Auto);
    let mut it = args;
    while let Some(a) = it.next() {
        match a.as_str() {
            "-o" | "--output" => out = Some(it.next().ok_or("-o needs a path")?.into()),
            "--fat16" => fat = FatChoice::Fat16,
            "--fat32" => fat = FatChoice::Fat32,
            "-h" | "--help" => return Err(String::new()),
            _ if a.starts_with('-') => return Err(format!("unknown option {a}")),
            _ if dir.is_none() => dir = Some(a.into()),
            _ => return Err(format!("unexpected argument {a}")),
        }
    }
    Ok(Args {
        dir: dir.ok_or("missing DIR")?,
        out: out.ok_or("missing -o IMAGE")?,
        fat,
    })
}

/// Writes the image leaving its zero runs as holes: mostly empty images
/// then take little disk space. Reads, and `dd`, still see the zeros.
fn write_sparse(path: &Path, image: &[u8]) -> std::io::Result<()> {
    let mut file = std::fs::File::create(path)?;
    file.set_len(image.len() as u64)?;
    for (i, chunk) in image.chunks(64 * 1024).enumerate() {
        if chunk.iter().any(|&b| b != 0) {
            file.seek(SeekFrom::Start(i as u64 * 64 * 1024))?;
            file.write_all(chunk)?;
        }
    }
    file.sync_all()
}

fn main() -> ExitCode {
    let args = match parse(std::env::args().skip(1)) {
        Ok(args) => args,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("taut-sdimage: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(if e.is_empty() { 0 } else { 2 });
        }
    };
    let built = sdimage::build_image_with_layout(&args.dir, args.fat)
        .and_then(|(image, layout)| write_sparse(&args.out, &image).map(|()| layout));
    match built {
        Ok(layout) => {
            println!(
                "{}: {} MiB, FAT{}, {}-byte clusters",
                args.out.display(),
                layout.image_bytes >> 20,
                if layout.fat32 { 32 } else { 16 },
                layout.bytes_per_cluster
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("taut-sdimage: {}: {e}", args.dir.display());
            ExitCode::FAILURE
        }
    }
}
