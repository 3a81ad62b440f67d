//! The auxiliary I2C master (RM registers 36–54, 99–103): slaves 0–3 transfer once per sample
//! (or every `1 + I2C_MST_DLY` samples when their I2C_MST_DELAY_CTRL bit is set), reads landing
//! in EXT_SENS_DATA; slave 4 makes single transfers and reports I2C_MST_STATUS.SLV4_DONE.
//!
//! The only device on the auxiliary bus is the AK8963 at 0x0C; any other address is not
//! acknowledged (I2C_MST_STATUS.SLVx_NACK; EXT_SENS_DATA keeps its old bytes).
//!
//! EXT_SENS_DATA is allocated to the enabled slaves in slave order by their LENG, starting at
//! EXT_SENS_DATA_00; a slave that is disabled keeps its space until all slaves are disabled or
//! I2C_MST_RST is written (RM section 4.25). Bytes past EXT_SENS_DATA_23 are lost. BYTE_SW swaps
//! the bytes of each word, words ending at odd slave register addresses (GRP = 0) or even ones
//! (GRP = 1); REG_DIS skips sending the register address.
//!
//! Slave 4 is started by writing I2C_SLV4_CTRL with EN set and completes at once if I2C_MST_EN is
//! set (otherwise as soon as it is): a driver that busy-waits on SLV4_DONE without a sample in
//! between (the `mpu9250` crate does) must see it done. EN clears when the transfer is done.

use core::ops::Range;

use margemu_protocol::regmap::mpu6xxx::{bits, reg, EXT_SENS_LEN};

use super::super::Bus;
use super::Mpu6xxx;
use margemu_protocol::regmap::ak8963::I2C_ADDRESS as AK_ADDRESS;

/// Master state that is not in registers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct AuxState {
    /// EXT_SENS_DATA bytes allocated to slaves 0..=3.
    alloc: [u8; 4],
    /// Samples seen while the master was enabled (for I2C_MST_DLY).
    samples: u32,
}

impl AuxState {
    /// The EXT_SENS_DATA bytes (0..24) allocated to `slave`.
    pub(super) fn ext_range(&self, slave: usize) -> Range<usize> {
        let start: usize = self.alloc.iter().take(slave).map(|&n| usize::from(n)).sum();
        let len = self.alloc.get(slave).map_or(0, |&n| usize::from(n));
        start.min(EXT_SENS_LEN)..(start + len).min(EXT_SENS_LEN)
    }
}

impl Mpu6xxx {
    /// The master runs if the part has one (not the ICM-20602) and USER_CTRL.I2C_MST_EN is set.
    fn master_enabled(&self) -> bool {
        self.config.variant.has_aux_master()
            && self.regs[usize::from(reg::USER_CTRL)] & bits::USER_I2C_MST_EN != 0
    }

    /// One sample of the master: slaves 0..=3 in order, reads into `ext` (EXT_SENS_DATA).
    pub(super) fn aux_sample(&mut self, ext: &mut [u8]) {
        if !self.master_enabled() {
            return;
        }
        self.slv4_transfer();
        let delay = self.regs[usize::from(reg::I2C_SLV4_CTRL)] & bits::SLV4_MST_DLY;
        let delayed_turn = self.aux.samples.is_multiple_of(u32::from(delay) + 1);
        self.aux.samples = self.aux.samples.wrapping_add(1);
        let delay_ctrl = self.regs[usize::from(reg::I2C_MST_DELAY_CTRL)];

        let ctrls: [u8; 4] =
            core::array::from_fn(|i| self.regs[usize::from(reg::I2C_SLV0_CTRL) + 3 * i]);
        if ctrls.iter().all(|c| c & bits::SLV_EN == 0) {
            self.aux.alloc = [0; 4];
            return;
        }
        for (alloc, ctrl) in self.aux.alloc.iter_mut().zip(ctrls) {
            if ctrl & bits::SLV_EN != 0 {
                *alloc = ctrl & bits::SLV_LENG;
            }
        }
        for (slave, ctrl) in ctrls.into_iter().enumerate() {
            let skip = delay_ctrl & (1 << slave) != 0 && !delayed_turn;
            if ctrl & bits::SLV_EN == 0 || skip {
                continue;
            }
            let range = self.aux.ext_range(slave);
            self.slave_transfer(slave, ctrl, &mut ext[range]);
        }
    }

    /// One transfer of slave 0..=3 with control byte `ctrl`; reads go to `out`.
    fn slave_transfer(&mut self, slave: usize, ctrl: u8, out: &mut [u8]) {
        let base = usize::from(reg::I2C_SLV0_ADDR) + 3 * slave;
        let (address, register) = (self.regs[base], self.regs[base + 1]);
        let data_out = self.regs[usize::from(reg::I2C_SLV0_DO) + slave];
        let len = usize::from(ctrl & bits::SLV_LENG);
        if len == 0 {
            return;
        }
        if !self.ak_device_present(address) {
            self.mst_status |= 1 << slave;
            return;
        }
        let reg_dis = ctrl & bits::SLV_REG_DIS != 0;
        if address & bits::SLV_RNW != 0 {
            let mut buf = [0u8; 15];
            let buf = &mut buf[..len];
            if let Some(ak) = &mut self.ak {
                if !reg_dis {
                    ak.set_pointer(register);
                }
                for byte in buf.iter_mut() {
                    *byte = ak.read_next();
                }
            }
            if ctrl & bits::SLV_BYTE_SW != 0 {
                swap_words(buf, register, ctrl & bits::SLV_GRP != 0);
            }
            let n = out.len().min(len);
            out[..n].copy_from_slice(&buf[..n]);
        } else {
            self.ak_write(register, data_out, reg_dis);
        }
    }

    /// A write on the auxiliary bus to the AK8963: `value` to `register`, or with `reg_dis` the
    /// single byte `value`, which the AK8963 takes as its register pointer.
    fn ak_write(&mut self, register: u8, value: u8, reg_dis: bool) {
        let Some(ak) = &mut self.ak else { return };
        if reg_dis {
            ak.set_pointer(value);
        } else {
            ak.write_register(register, value);
            self.log_write(Bus::Aux, AK_ADDRESS, register, value);
        }
    }

    /// Runs slave 4's transfer if I2C_SLV4_CTRL.EN is set and the master is enabled.
    pub(super) fn slv4_transfer(&mut self) {
        let ctrl_addr = usize::from(reg::I2C_SLV4_CTRL);
        let ctrl = self.regs[ctrl_addr];
        if ctrl & bits::SLV_EN == 0 || !self.master_enabled() {
            return;
        }
        self.regs[ctrl_addr] &= !bits::SLV_EN;
        let address = self.regs[usize::from(reg::I2C_SLV4_ADDR)];
        let register = self.regs[usize::from(reg::I2C_SLV4_REG)];
        let data_out = self.regs[usize::from(reg::I2C_SLV4_DO)];
        let reg_dis = ctrl & bits::SLV_REG_DIS != 0;
        if !self.ak_device_present(address) {
            self.mst_status |= bits::MST_SLV4_NACK | bits::MST_SLV4_DONE;
            return;
        }
        if address & bits::SLV_RNW != 0 {
            if let Some(ak) = &mut self.ak {
                if !reg_dis {
                    ak.set_pointer(register);
                }
                self.regs[usize::from(reg::I2C_SLV4_DI)] = ak.read_next();
            }
        } else {
            self.ak_write(register, data_out, reg_dis);
        }
        self.mst_status |= bits::MST_SLV4_DONE;
    }
}

/// Swaps the bytes of each word of `buf`, read from slave register `first` onwards; words end at
/// odd register addresses, or at even ones with `grp`. A byte without its partner stays.
fn swap_words(buf: &mut [u8], first: u8, grp: bool) {
    let starts_word = (first & 1 == 0) != grp;
    let skip = usize::from(!starts_word);
    let mut i = skip;
    while i + 1 < buf.len() {
        buf.swap(i, i + 1);
        i += 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn allocation_is_cumulative_and_clipped() {
        let aux = AuxState {
            alloc: [7, 0, 15, 15],
            samples: 0,
        };
        assert_eq!(aux.ext_range(0), 0..7);
        assert_eq!(aux.ext_range(1), 7..7);
        assert_eq!(aux.ext_range(2), 7..22);
        assert_eq!(aux.ext_range(3), 22..24);
        assert_eq!(aux.ext_range(9), 24..24);
    }

    #[test]
    fn word_swapping_follows_grp() {
        // From AK8963 0x03 (odd) with GRP = 1 (words end at even addresses): 03-04, 05-06, 07-08.
        let mut buf = [1, 2, 3, 4, 5, 6, 7];
        swap_words(&mut buf, 0x03, true);
        assert_eq!(buf, [2, 1, 4, 3, 6, 5, 7]);
        // Same start with GRP = 0 (words end at odd addresses): 03 alone, 04-05, 06-07, 08-09.
        let mut buf = [1, 2, 3, 4, 5, 6, 7];
        swap_words(&mut buf, 0x03, false);
        assert_eq!(buf, [1, 3, 2, 5, 4, 7, 6]);
        let mut buf = [1, 2, 3];
        swap_words(&mut buf, 0x02, false);
        assert_eq!(buf, [2, 1, 3]);
    }
}
