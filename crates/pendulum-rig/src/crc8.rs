//! CRC-8 of the `sd-v2` frames: polynomial 0x07, init 0x00, no reflection, no final xor
//! (a.k.a. CRC-8/SMBUS).

/// Byte-at-a-time table, built at compile time.
const TABLE: [u8; 256] = build_table();

const fn build_table() -> [u8; 256] {
    let mut table = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = i as u8;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 0x80 != 0 {
                (crc << 1) ^ 0x07
            } else {
                crc << 1
            };
            bit += 1;
        }
        table[i] = crc;
        i += 1;
    }
    table
}

/// CRC-8/SMBUS of `data`.
pub fn crc8(data: &[u8]) -> u8 {
    data.iter().fold(0u8, |crc, &b| TABLE[(crc ^ b) as usize])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_value() {
        assert_eq!(crc8(b"123456789"), 0xF4);
        assert_eq!(crc8(b""), 0);
    }

    #[test]
    fn detects_every_single_byte_change() {
        let data = [3u8, 2, 1, 2, 3, 4, 5, 6];
        let good = crc8(&data);
        for i in 0..data.len() {
            for v in 0..=255u8 {
                if v == data[i] {
                    continue;
                }
                let mut d = data;
                d[i] = v;
                assert_ne!(crc8(&d), good);
            }
        }
    }
}
