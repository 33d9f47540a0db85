#!/usr/bin/env python3
"""Writes the `fat` target's seeds (fuzz/seeds/fat/): two tiny card images
that mount and hold PARAM.TXT and PORADI.TXT (two clusters), one FAT16
without a partition table and one FAT32 behind an MBR. The target repeats
its input past the end, block N being block N mod (input blocks), so a few
blocks stand for a whole volume: the layout puts boot sector, first FAT
block, root directory and data on distinct blocks. Run it from anywhere."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
PARAM = b"tvar = 6\r\npocet_hrebiku = 24\r\npolomer_matrice = 20.0   # cm\r\n"
PORADI = (b"30,0,7,13,23,2,17,5,11,19,3,21,9,15,1,8,14,22,6,12,18,4,10,16,20,2,9,17,23,5,13\n"
          + b" " * 520)  # two clusters


def block():
    return bytearray(512)


def boot(reserved, fats, root_entries, total, fat_blocks, fat32, hidden=0):
    b = block()
    b[0:3] = b"\xEB\x3C\x90"
    b[3:11] = b"TAUTSEED"
    struct.pack_into("<HBHBH", b, 11, 512, 1, reserved, fats, root_entries)
    b[21] = 0xF8
    if fat32:
        struct.pack_into("<I", b, 28, hidden)
        struct.pack_into("<I", b, 32, total)
        struct.pack_into("<I", b, 36, fat_blocks)
        struct.pack_into("<I", b, 44, 2)  # root directory cluster
        b[82:90] = b"FAT32   "
    else:
        struct.pack_into("<H", b, 19, total)
        struct.pack_into("<H", b, 22, fat_blocks)
        b[54:62] = b"FAT16   "
    b[510:512] = b"\x55\xAA"
    return b


def entry(name, attr, cluster, size):
    e = bytearray(32)
    e[0:11] = name
    e[11] = attr
    struct.pack_into("<H", e, 20, cluster >> 16)
    struct.pack_into("<H", e, 26, cluster & 0xFFFF)
    struct.pack_into("<I", e, 28, size)
    return e


def root(first):
    """Label, a deleted entry, PARAM.TXT at `first`, PORADI.TXT after it."""
    b = block()
    b[0:32] = entry(b"TAUT CARD  ", 0x08, 0, 0)
    b[32:64] = entry(b"\xE5ARAM   TXT", 0x20, first, len(PARAM))
    b[64:96] = entry(b"PARAM   TXT", 0x20, first, len(PARAM))
    b[96:128] = entry(b"PORADI  TXT", 0x20, first + 1, len(PORADI))
    return b


def image(blocks):
    """`blocks` {lba: content} on the fewest blocks n that put every lba
    (at lba mod n) on a block of its own."""
    n = next(n for n in range(len(blocks), 64) if len({lba % n for lba in blocks}) == len(blocks))
    img = [block() for _ in range(n)]
    for lba, content in blocks.items():
        img[lba % n][: len(content)] = content
    return b"".join(img)


def fat16():
    reserved, clusters = 1, 4200
    fat_blocks = -(-(clusters + 2) * 2 // 512)
    total = reserved + fat_blocks + 1 + clusters
    fat = struct.pack("<5H", 0xFFF8, 0xFFFF, 0xFFFF, 4, 0xFFFF)
    data = reserved + fat_blocks + 1
    return image({0: boot(reserved, 1, 16, total, fat_blocks, False), reserved: fat,
                  data - 1: root(2), data: PARAM, data + 1: PORADI[:512],
                  data + 2: PORADI[512:]})


def fat32():
    start, reserved, clusters = 1, 2, 65600
    fat_blocks = -(-(clusters + 2) * 4 // 512)
    total = reserved + fat_blocks + clusters
    mbr = block()
    mbr[446 + 4] = 0x0C
    struct.pack_into("<II", mbr, 446 + 8, start, total)
    mbr[510:512] = b"\x55\xAA"
    eoc = 0x0FFFFFFF
    fat = struct.pack("<6I", 0x0FFFFFF8, eoc, eoc, eoc, 5, eoc)
    data = start + reserved + fat_blocks
    return image({0: mbr, start: boot(reserved, 1, 0, total, fat_blocks, True, start),
                  start + reserved: fat, data: root(3), data + 1: PARAM,
                  data + 2: PORADI[:512], data + 3: PORADI[512:]})


if __name__ == "__main__":
    out = os.path.join(HERE, "fat")
    os.makedirs(out, exist_ok=True)
    for name, img in (("fat16", fat16()), ("fat32-mbr", fat32())):
        with open(os.path.join(out, name), "wb") as f:
            f.write(img)
