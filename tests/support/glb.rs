//! Binary glTF (.glb) in the tests: its JSON and binary chunks taken apart and put together
//! again, to read what the exporter wrote and to build models that break one rule.

use serde_json::Value;

/// The JSON chunk of a .glb.
pub fn json(bytes: &[u8]) -> Value {
    split(bytes).0
}

/// The JSON and binary chunks of a .glb.
pub fn split(bytes: &[u8]) -> (Value, Vec<u8>) {
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + n]).unwrap();
    (json, bytes.get(28 + n..).unwrap_or_default().to_vec())
}

/// A .glb of `json` and the binary chunk `bin`, each padded to 4 bytes as the format asks.
pub fn join(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while b.len() % 4 != 0 {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}
