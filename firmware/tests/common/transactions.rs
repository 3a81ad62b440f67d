//! Byte-level bus transactions, shared by every chip's test crate (included with `#[path]`).
//!
//! SPI transactions are written as the bytes on MOSI and the bytes expected on MISO, aligned:
//! `spi(&mut chip, &[0x80 | 0x75, 0x00]) == [0x00, 0x71]`.

#![allow(dead_code)]

use margemu_firmware::chip::{I2cTarget, SpiTarget};

/// One SPI transaction: MOSI bytes in, MISO bytes out, aligned byte for byte.
pub fn spi(chip: &mut (impl SpiTarget + ?Sized), mosi: &[u8]) -> Vec<u8> {
    let mut miso = vec![chip.select()];
    for (i, &byte) in mosi.iter().enumerate() {
        let next = chip.exchange(byte);
        if i + 1 < mosi.len() {
            miso.push(next);
        }
    }
    chip.deselect();
    miso.truncate(mosi.len());
    miso
}

/// Reads `n` registers from `addr` over SPI.
pub fn spi_read(chip: &mut (impl SpiTarget + ?Sized), addr: u8, n: usize) -> Vec<u8> {
    let mut mosi = vec![0x80 | addr];
    mosi.resize(n + 1, 0x00);
    spi(chip, &mosi)[1..].to_vec()
}

/// Writes `values` from `addr` on over SPI.
pub fn spi_write(chip: &mut (impl SpiTarget + ?Sized), addr: u8, values: &[u8]) {
    let mut mosi = vec![addr];
    mosi.extend_from_slice(values);
    assert_eq!(
        spi(chip, &mosi),
        vec![0; mosi.len()],
        "MISO is 0x00 during writes"
    );
}

/// An I2C write transaction; returns the ACK of the address and each byte.
pub fn i2c_write(chip: &mut impl I2cTarget, address: u8, bytes: &[u8]) -> Vec<bool> {
    let mut acks = vec![chip.start(address, false)];
    acks.extend(bytes.iter().map(|&b| chip.write(b)));
    chip.stop();
    acks
}

/// Register read over I2C: write the pointer, repeated START, read `n` bytes, STOP.
/// `None` if the address was not acknowledged.
pub fn i2c_read(chip: &mut impl I2cTarget, address: u8, reg: u8, n: usize) -> Option<Vec<u8>> {
    if !chip.start(address, false) {
        chip.stop();
        return None;
    }
    chip.write(reg);
    assert!(chip.start(address, true), "repeated START");
    let bytes = (0..n).map(|_| chip.read()).collect();
    chip.stop();
    Some(bytes)
}
