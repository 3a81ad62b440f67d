//! PX4's IST8310 driver: SRST, then 50 ms later WAI and CNTL2.SRST == 0, configuration by
//! read–modify–write with a check of every configured register, then single measurements 20 ms
//! apart, each read as 7 bytes from STAT1 that must report DRDY.

use super::*;

/// Registers PX4 configures: (register, bits set, bits cleared).
const CONFIG: [(u8, u8, u8); 4] = [
    (0x0B, 0x00, 0x08), // CNTL2: DRDY pin disabled
    (0x0D, 0x70, 0x00), // CNTL3: 16-bit output bits (stored only)
    (0x41, 0x24, 0x1B), // AVGCNTL: 16 times
    (0x42, 0xC0, 0x00), // PDCNTL: normal
];

fn configure(mag: &mut Ist8310) {
    for (reg, set, clear) in CONFIG {
        let old = read_regs(mag, reg, 1)[0];
        let new = (old & !clear) | set;
        if new != old {
            write_reg(mag, reg, new);
        }
    }
    for (reg, set, clear) in CONFIG {
        let v = read_regs(mag, reg, 1)[0];
        assert_eq!((v & set, v & clear), (set, 0), "register {reg:#04x}");
    }
}

#[test]
fn reset_configure_and_measure_with_drdy() {
    let mut mag = Ist8310::new();
    write_reg(&mut mag, 0x0B, 0x01);
    let mut t = 50 * MS;
    tick(&mut mag, t);
    assert_eq!(read_regs(&mut mag, 0x00, 1), [0x10]);
    assert_eq!(read_regs(&mut mag, 0x0B, 1)[0] & 0x01, 0);
    t += 10 * MS;
    tick(&mut mag, t);
    configure(&mut mag);
    let fields = samples(50);
    write_reg(&mut mag, 0x0A, 0x01);
    for field in &fields {
        mag.advance(t + 7 * MS, *field);
        t += 20 * MS;
        tick(&mut mag, t);
        let b = read_regs(&mut mag, 0x02, 7);
        assert_eq!(b[0] & 0x01, 0x01, "DRDY");
        assert!(within_one_lsb(decode(&b[1..]), *field));
        write_reg(&mut mag, 0x0A, 0x01);
    }
}
