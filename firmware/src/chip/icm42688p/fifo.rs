//! The 2 KB FIFO (DS: FIFO, packet structure, FIFO_CONFIG, FIFO_CONFIG1–3, FIFO_COUNT,
//! FIFO_LOST_PKT).
//!
//! FIFO_CONFIG.FIFO_MODE 00 (bypass) pushes nothing; 01 (stream) drops the oldest whole packets
//! to make room; 1x (stop on full) drops the new packet. Dropped packets count in
//! FIFO_LOST_PKT0/1 and raise FIFO_FULL_INT, as does a FIFO left exactly full. One packet per
//! latch, chosen by FIFO_CONFIG1 (FIFO_TEMP_EN and FIFO_TMST_FSYNC_EN are stored only: every
//! packet carries temperature, packets 3 and 4 a timestamp):
//!
//! | FIFO_CONFIG1          | packet | bytes | header            | content                          |
//! |-----------------------|--------|-------|-------------------|----------------------------------|
//! | ACCEL_EN              | 1      | 8     | 0x40              | accel, temp (8-bit)              |
//! | GYRO_EN               | 2      | 8     | 0x20              | gyro, temp (8-bit)               |
//! | ACCEL_EN + GYRO_EN    | 3      | 16    | 0x68              | accel, gyro, temp (8-bit), time  |
//! | HIRES_EN (+ both)     | 4      | 20    | 0x78              | accel, gyro bits 19:4, temp (16-bit), time, 3 × (accel[3:0] ‖ gyro[3:0]) |
//!
//! Headers gain HEADER_ODR_ACCEL/GYRO when the ODR differs from the previous packet's since the
//! last flush. 16-bit fields (and the timestamp) follow SENSOR_DATA_ENDIAN. The timestamp is the
//! ODR time in µs or 16 µs units (TMST_CONFIG.TMST_RES), or its change since the last packet
//! (TMST_DELTA_EN), modulo 2^16; 0 with TMST_EN clear. A sensor that is off fills its fields with
//! −32768 (20-bit: −524288). FIFO_DATA reads 0xFF when empty (HEADER_MSG set).
//!
//! The FIFO threshold (FIFO_CONFIG2/3, in the unit of FIFO_COUNT) raises FIFO_THS_INT when a
//! push brings the count to it or above; with FIFO_WM_GT_TH at every push while at or above.
//! A threshold of 0 never fires.

use margemu_protocol::regmap::icm42688p::convert::fifo_temp8;
use margemu_protocol::regmap::icm42688p::{bank0, bits, packet, FIFO_SIZE};

use super::Icm42688p;

const MAX_PACKETS: usize = FIFO_SIZE / packet::SINGLE_LEN;

/// The FIFO storage: a byte ring plus the length of each packet in it.
#[derive(Clone, Debug)]
pub(super) struct Fifo {
    buf: [u8; FIFO_SIZE],
    /// Start of the oldest packet.
    head: usize,
    /// Bytes from `head` on, the oldest packet's read part included.
    len: usize,
    lens: [u8; MAX_PACKETS],
    lens_head: usize,
    packets: usize,
    /// Bytes of the oldest packet already read.
    cursor: usize,
    lost: u16,
    /// ODR codes (gyro, accel) of the last packet since the flush.
    last_odr: Option<(u8, u8)>,
    last_time_ns: Option<u64>,
}

impl Fifo {
    pub(super) fn new() -> Self {
        Self {
            buf: [0; FIFO_SIZE],
            head: 0,
            len: 0,
            lens: [0; MAX_PACKETS],
            lens_head: 0,
            packets: 0,
            cursor: 0,
            lost: 0,
            last_odr: None,
            last_time_ns: None,
        }
    }

    /// Empties the FIFO and its history (flush, reset).
    pub(super) fn flush(&mut self) {
        self.head = 0;
        self.len = 0;
        self.lens_head = 0;
        self.packets = 0;
        self.cursor = 0;
        self.lost = 0;
        self.last_odr = None;
        self.last_time_ns = None;
    }

    /// Unread bytes.
    pub(super) fn bytes(&self) -> usize {
        self.len - self.cursor
    }

    /// Packets not completely read.
    pub(super) fn records(&self) -> usize {
        self.packets
    }

    pub(super) fn lost(&self) -> u16 {
        self.lost
    }

    /// The next byte a read returns.
    pub(super) fn peek(&self) -> Option<u8> {
        (self.bytes() > 0).then(|| self.buf[(self.head + self.cursor) % FIFO_SIZE])
    }

    /// The next byte was read.
    pub(super) fn pop(&mut self) {
        if self.bytes() == 0 {
            return;
        }
        self.cursor += 1;
        if self.cursor >= usize::from(self.lens[self.lens_head]) {
            self.drop_oldest();
        }
    }

    /// A transaction ended: without `resume`, a partly read packet is read again from its start.
    pub(super) fn end_transaction(&mut self, resume: bool) {
        if !resume {
            self.cursor = 0;
        }
    }

    fn drop_oldest(&mut self) {
        if self.packets == 0 {
            return;
        }
        let n = usize::from(self.lens[self.lens_head]);
        self.head = (self.head + n) % FIFO_SIZE;
        self.len = self.len.saturating_sub(n);
        self.lens_head = (self.lens_head + 1) % MAX_PACKETS;
        self.packets -= 1;
        self.cursor = 0;
    }

    fn fits(&self, n: usize) -> bool {
        self.len + n <= FIFO_SIZE && self.packets < MAX_PACKETS
    }

    /// Appends `packet`; `stream` drops old packets to make room. Returns packets lost.
    fn push(&mut self, packet: &[u8], stream: bool) -> u16 {
        let mut lost = 0u16;
        if packet.len() > FIFO_SIZE || packet.is_empty() {
            return 0;
        }
        while !self.fits(packet.len()) {
            if !stream || self.packets == 0 {
                self.lost = self.lost.saturating_add(1);
                return 1;
            }
            self.drop_oldest();
            lost = lost.saturating_add(1);
        }
        for (i, &byte) in packet.iter().enumerate() {
            self.buf[(self.head + self.len + i) % FIFO_SIZE] = byte;
        }
        self.len += packet.len();
        self.lens[(self.lens_head + self.packets) % MAX_PACKETS] = packet.len() as u8;
        self.packets += 1;
        self.lost = self.lost.saturating_add(lost);
        lost
    }
}

/// What a packet is built from: the big-endian data registers and the 20-bit values.
pub(super) struct PacketSource<'a> {
    /// TEMP_DATA, ACCEL_DATA, GYRO_DATA, big-endian (−32768 for a sensor off).
    pub data: &'a [u8; 14],
    /// 20-bit accel then gyro (−524288 for a sensor off).
    pub hires: [i32; 6],
}

impl Icm42688p {
    /// The FIFO count in records or bytes.
    pub(super) fn fifo_count(&self, records: bool) -> u16 {
        let n = if records {
            self.fifo.records()
        } else {
            self.fifo.bytes()
        };
        n as u16
    }

    /// Pushes the packet of one sample, if the FIFO is on and configured for one.
    pub(super) fn fifo_push_sample(&mut self, src: &PacketSource) {
        let mode = self.reg0(bank0::FIFO_CONFIG) & bits::FIFO_MODE;
        if mode == 0 {
            return;
        }
        let mut out = [0u8; packet::HIRES_LEN];
        let Some(n) = self.build_packet(src, &mut out) else {
            return;
        };
        let records = self.reg0(bank0::INTF_CONFIG0) & bits::FIFO_COUNT_REC != 0;
        let before = self.fifo_count(records);
        let packet = out.get(..n).unwrap_or_default();
        let stream = mode == bits::FIFO_MODE_STREAM;
        let mut lost = self.fifo.push(packet, stream);
        // The overflow fault: copies of the packet until one does not fit (`faults.rs`).
        let mut copies = if self.fault.fifo_overflow {
            MAX_PACKETS + 1
        } else {
            0
        };
        while lost == 0 && copies > 0 {
            lost = self.fifo.push(packet, stream);
            copies -= 1;
        }
        if lost > 0 || self.fifo.bytes() == FIFO_SIZE {
            self.raise_interrupt(bits::FIFO_FULL_INT);
        }
        let after = self.fifo_count(records);
        let cfg1 = self.reg0(bank0::FIFO_CONFIG1);
        let wm = u16::from(self.reg0(bank0::FIFO_CONFIG3) & 0x0F) << 8
            | u16::from(self.reg0(bank0::FIFO_CONFIG2));
        let every = cfg1 & bits::FIFO_WM_GT_TH != 0;
        if wm > 0 && after >= wm && (every || before < wm) {
            self.raise_interrupt(bits::FIFO_THS_INT);
        }
    }

    /// Writes one packet into `out`; returns its length, `None` if no sensor is in the FIFO.
    fn build_packet(
        &mut self,
        src: &PacketSource,
        out: &mut [u8; packet::HIRES_LEN],
    ) -> Option<usize> {
        let cfg1 = self.reg0(bank0::FIFO_CONFIG1);
        let accel = cfg1 & bits::FIFO_ACCEL_EN != 0;
        let gyro = cfg1 & bits::FIFO_GYRO_EN != 0;
        let hires = cfg1 & bits::FIFO_HIRES_EN != 0;
        if !(accel || gyro || hires) {
            return None;
        }
        let little = self.reg0(bank0::INTF_CONFIG0) & bits::SENSOR_DATA_ENDIAN == 0;
        let pair = |hi: u8, lo: u8| if little { [lo, hi] } else { [hi, lo] };
        let d = src.data;
        let temp16 = i16::from_be_bytes([d[0], d[1]]);
        let mut header = self.odr_change_bits(accel || hires, gyro || hires);
        let n = if hires {
            header |= bits::HEADER_20 | bits::HEADER_TIMESTAMP_ODR;
            header |= if accel { bits::HEADER_ACCEL } else { 0 };
            header |= if gyro { bits::HEADER_GYRO } else { 0 };
            let v = src.hires;
            for (i, x) in v.iter().enumerate() {
                let [_, _, hi, lo] = ((x >> 4) as u32).to_be_bytes();
                out[1 + 2 * i..3 + 2 * i].copy_from_slice(&pair(hi, lo));
            }
            out[13..15].copy_from_slice(&pair(d[0], d[1]));
            let t = self.fifo_timestamp();
            out[15..17].copy_from_slice(&pair((t >> 8) as u8, t as u8));
            for axis in 0..3 {
                out[17 + axis] = ((v[axis] & 0x0F) << 4 | (v[3 + axis] & 0x0F)) as u8;
            }
            packet::HIRES_LEN
        } else if accel && gyro {
            header |= bits::HEADER_ACCEL | bits::HEADER_GYRO | bits::HEADER_TIMESTAMP_ODR;
            for i in 0..6 {
                out[1 + 2 * i..3 + 2 * i].copy_from_slice(&pair(d[2 + 2 * i], d[3 + 2 * i]));
            }
            out[13] = fifo_temp8(temp16) as u8;
            let t = self.fifo_timestamp();
            out[14..16].copy_from_slice(&pair((t >> 8) as u8, t as u8));
            packet::BOTH_LEN
        } else {
            header |= if accel {
                bits::HEADER_ACCEL
            } else {
                bits::HEADER_GYRO
            };
            let first = if accel { 2 } else { 8 };
            for i in 0..3 {
                let at = first + 2 * i;
                out[1 + 2 * i..3 + 2 * i].copy_from_slice(&pair(d[at], d[at + 1]));
            }
            out[7] = fifo_temp8(temp16) as u8;
            packet::SINGLE_LEN
        };
        out[0] = header;
        Some(n)
    }

    /// HEADER_ODR_ACCEL/GYRO for the sensors in the packet whose ODR changed since the last one.
    fn odr_change_bits(&mut self, accel: bool, gyro: bool) -> u8 {
        let odr = (
            self.reg0(bank0::GYRO_CONFIG0) & 0x0F,
            self.reg0(bank0::ACCEL_CONFIG0) & 0x0F,
        );
        let mut header = 0;
        if let Some((g, a)) = self.fifo.last_odr {
            if gyro && g != odr.0 {
                header |= bits::HEADER_ODR_GYRO;
            }
            if accel && a != odr.1 {
                header |= bits::HEADER_ODR_ACCEL;
            }
        }
        self.fifo.last_odr = Some(odr);
        header
    }

    /// The 16-bit FIFO timestamp of a packet pushed now.
    fn fifo_timestamp(&mut self) -> u16 {
        let cfg = self.reg0(bank0::TMST_CONFIG);
        let unit_ns = if cfg & bits::TMST_RES != 0 {
            16_000
        } else {
            1_000
        };
        let now = self.now_ns;
        let previous = self.fifo.last_time_ns.replace(now);
        if cfg & bits::TMST_EN == 0 {
            return 0;
        }
        let ticks = if cfg & bits::TMST_DELTA_EN != 0 {
            (now / unit_ns).saturating_sub(previous.map_or(now / unit_ns, |p| p / unit_ns))
        } else {
            now / unit_ns
        };
        ticks as u16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_keeps_packets_whole() {
        let mut fifo = Fifo::new();
        for round in 0..300u16 {
            assert_eq!(fifo.push(&[round as u8; 8], false), 0);
            assert_eq!((fifo.bytes(), fifo.records()), (8, 1));
            for _ in 0..8 {
                assert_eq!(fifo.peek(), Some(round as u8));
                fifo.pop();
            }
            assert_eq!(fifo.peek(), None);
        }
    }

    #[test]
    fn partial_reads_rewind_or_resume() {
        let mut fifo = Fifo::new();
        fifo.push(&[1, 2, 3, 4, 5, 6, 7, 8], false);
        fifo.pop();
        fifo.pop();
        fifo.end_transaction(false);
        assert_eq!((fifo.peek(), fifo.bytes()), (Some(1), 8));
        fifo.pop();
        fifo.end_transaction(true);
        assert_eq!((fifo.peek(), fifo.bytes()), (Some(2), 7));
    }

    #[test]
    fn overflow_stream_and_stop_on_full() {
        let mut fifo = Fifo::new();
        for i in 0..128u8 {
            assert_eq!(fifo.push(&[i; 16], false), 0);
        }
        assert_eq!(fifo.push(&[0xAA; 16], false), 1);
        assert_eq!((fifo.peek(), fifo.lost()), (Some(0), 1));
        assert_eq!(
            fifo.push(&[0xBB; 20], true),
            2,
            "20 bytes need two 16-byte packets out"
        );
        assert_eq!((fifo.peek(), fifo.lost(), fifo.bytes()), (Some(2), 3, 2036));
    }
}
