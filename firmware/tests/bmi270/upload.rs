//! The configuration upload and INTERNAL_STATUS.

use super::*;

#[test]
fn the_328_byte_file_in_one_burst_initializes() {
    let mut c = spi_chip();
    upload(&mut c, &config_file(328));
    assert_eq!(read1(&mut c, 0x21), 0x01);
}

#[test]
fn status_is_not_init_during_the_upload() {
    let mut c = spi_chip();
    spi_write(&mut c, 0x59, &[0x00]);
    spi_write(&mut c, 0x5E, &config_file(328));
    assert_eq!(read1(&mut c, 0x21), 0x00);
    spi_write(&mut c, 0x59, &[0x01]);
    assert_eq!(read1(&mut c, 0x21), 0x01);
    assert_eq!(read1(&mut c, 0x59), 0x01); // INIT_CTRL reads back
}

#[test]
fn a_truncated_upload_reports_init_err() {
    let mut c = spi_chip();
    upload(&mut c, &config_file(327));
    assert_eq!(read1(&mut c, 0x21) & 0x0F, 0x02);
    let mut c = spi_chip();
    upload(&mut c, &config_file(8192 - 2));
    assert_eq!(read1(&mut c, 0x21) & 0x0F, 0x02);
}

#[test]
fn no_upload_reports_init_err() {
    let mut c = spi_chip();
    spi_write(&mut c, 0x59, &[0x01]);
    assert_eq!(read1(&mut c, 0x21), 0x02);
}

#[test]
fn a_retry_after_a_failed_upload_succeeds() {
    let mut c = spi_chip();
    upload(&mut c, &config_file(100));
    assert_eq!(read1(&mut c, 0x21), 0x02);
    upload(&mut c, &config_file(328));
    assert_eq!(read1(&mut c, 0x21), 0x01);
}

#[test]
fn the_8k_file_in_chunks_through_init_addr() {
    let file = config_file(8192);
    for chunk_len in [32usize, 256, 1024] {
        let mut c = spi_chip();
        spi_write(&mut c, 0x7C, &[0x00]);
        spi_write(&mut c, 0x59, &[0x00]);
        for (i, chunk) in file.chunks(chunk_len).enumerate() {
            let word = i * chunk_len / 2;
            spi_write(&mut c, 0x5B, &[(word & 0x0F) as u8, (word >> 4) as u8]);
            spi_write(&mut c, 0x5E, chunk);
        }
        let last = (8192 - chunk_len) / 2; // word offset of the last chunk
        assert_eq!(
            read(&mut c, 0x5B, 2),
            [(last & 0x0F) as u8, (last >> 4) as u8]
        );
        spi_write(&mut c, 0x59, &[0x01]);
        assert_eq!(read1(&mut c, 0x21), 0x01, "chunks of {chunk_len}");
    }
}

#[test]
fn chunks_without_moving_init_addr_overwrite_the_start() {
    let file = config_file(8192);
    let mut c = spi_chip();
    spi_write(&mut c, 0x59, &[0x00]);
    for chunk in file.chunks(256) {
        spi_write(&mut c, 0x5E, chunk); // INIT_ADDR stays 0: every chunk lands at offset 0
    }
    spi_write(&mut c, 0x59, &[0x01]);
    assert_eq!(read1(&mut c, 0x21), 0x02);
}

#[test]
fn init_data_written_while_init_ctrl_is_1_is_ignored() {
    let mut c = spi_chip();
    spi_write(&mut c, 0x59, &[0x00]);
    spi_write(&mut c, 0x59, &[0x01]); // 0 → 1 with nothing loaded
    spi_write(&mut c, 0x5E, &config_file(328));
    spi_write(&mut c, 0x59, &[0x01]); // no 0 → 1 edge: status unchanged
    assert_eq!(read1(&mut c, 0x21), 0x02);
}
