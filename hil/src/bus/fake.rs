//! Fake targets for the adapters' tests, logging every bus event: a byte echo and a small
//! register file in the MPU-9250's style.

use margemu_firmware::chip::{I2cTarget, SpiTarget};

/// One event seen by a fake target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    Select,
    Exchange(u8),
    Deselect,
    /// Address and read flag.
    Start(u8, bool),
    Write(u8),
    Read,
    Stop,
}

/// SPI target whose MISO for each byte is the MOSI of the byte before; the first byte of a
/// transaction reads [`Echo::FIRST`].
#[derive(Default)]
pub struct Echo {
    pub log: Vec<Event>,
}

impl Echo {
    pub const FIRST: u8 = 0xA5;
}

impl SpiTarget for Echo {
    fn select(&mut self) -> u8 {
        self.log.push(Event::Select);
        Self::FIRST
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        self.log.push(Event::Exchange(mosi));
        mosi
    }

    fn deselect(&mut self) {
        self.log.push(Event::Deselect);
    }
}

#[derive(Default)]
enum Phase {
    /// SPI: the next byte is the command; I2C: the next written byte is the pointer.
    #[default]
    Command,
    Reading,
    Writing,
    /// I2C: address not acknowledged, ignore bytes until the next START.
    Ignoring,
}

/// Sixteen registers with an auto-incrementing pointer (wrapping at 16).
///
/// SPI: the first byte is `0x80 | reg` to read or `reg` to write. I2C at its address
/// ([`Regs::ADDRESS`] unless made with [`Regs::counting_at`]): the first byte written after a
/// START sets the pointer; [`Regs::READ_ONLY`] refuses writes (NACK).
#[derive(Default)]
pub struct Regs {
    pub regs: [u8; 16],
    pub log: Vec<Event>,
    address: u8,
    ptr: usize,
    phase: Phase,
}

impl Regs {
    pub const ADDRESS: u8 = 0x68;
    pub const READ_ONLY: usize = 0x0F;

    /// Registers holding `0x10 + i`, at [`Regs::ADDRESS`].
    pub fn counting() -> Self {
        Self::counting_at(Self::ADDRESS, 0x10)
    }

    /// Registers holding `first + i`, answering I2C `address`.
    pub fn counting_at(address: u8, first: u8) -> Self {
        Self {
            regs: core::array::from_fn(|i| first.wrapping_add(i as u8)),
            address,
            ..Self::default()
        }
    }

    fn next(&mut self) -> u8 {
        let value = self.regs[self.ptr];
        self.ptr = (self.ptr + 1) % 16;
        value
    }

    fn store(&mut self, value: u8) -> bool {
        if self.ptr == Self::READ_ONLY {
            return false;
        }
        self.regs[self.ptr] = value;
        self.ptr = (self.ptr + 1) % 16;
        true
    }
}

impl SpiTarget for Regs {
    fn select(&mut self) -> u8 {
        self.log.push(Event::Select);
        self.phase = Phase::Command;
        0x00
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        self.log.push(Event::Exchange(mosi));
        match self.phase {
            Phase::Command => {
                self.ptr = usize::from(mosi & 0x0F);
                if mosi & 0x80 != 0 {
                    self.phase = Phase::Reading;
                    self.next()
                } else {
                    self.phase = Phase::Writing;
                    0x00
                }
            }
            Phase::Reading => self.next(),
            Phase::Writing => {
                self.store(mosi);
                0x00
            }
            Phase::Ignoring => 0x00,
        }
    }

    fn deselect(&mut self) {
        self.log.push(Event::Deselect);
    }
}

impl I2cTarget for Regs {
    fn start(&mut self, address: u8, read: bool) -> bool {
        self.log.push(Event::Start(address, read));
        let ack = address == self.address;
        self.phase = match (ack, read) {
            (false, _) => Phase::Ignoring,
            (true, true) => Phase::Reading,
            (true, false) => Phase::Command,
        };
        ack
    }

    fn write(&mut self, byte: u8) -> bool {
        self.log.push(Event::Write(byte));
        match self.phase {
            Phase::Command => {
                self.ptr = usize::from(byte & 0x0F);
                self.phase = Phase::Writing;
                true
            }
            Phase::Writing => self.store(byte),
            Phase::Reading | Phase::Ignoring => false,
        }
    }

    fn read(&mut self) -> u8 {
        self.log.push(Event::Read);
        match self.phase {
            Phase::Ignoring => 0xFF,
            _ => self.next(),
        }
    }

    fn stop(&mut self) {
        self.log.push(Event::Stop);
        self.phase = Phase::Ignoring;
    }
}
