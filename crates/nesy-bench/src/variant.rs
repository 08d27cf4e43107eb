//! A variant is a method with its settings, written `method` or `method+key=value+…` on the
//! command line (`nesycr+verification=off`, `nesycr+noise=op-drop=0.1;op-flip=0.05`). Units
//! of one variant share a configuration hash; a resumed run refuses records of a variant
//! whose settings changed.

use std::collections::BTreeMap;
use std::fmt;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::error::BenchError;

/// A method and its settings.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Variant {
    /// The method's name (`nesycr`, `imitation`, …).
    pub method: String,
    /// Settings by key, as given (validated by the method).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub options: BTreeMap<String, String>,
}

impl Variant {
    /// A variant with no settings.
    pub fn plain(method: &str) -> Variant {
        Variant {
            method: method.to_owned(),
            options: BTreeMap::new(),
        }
    }

    /// The same method with one more setting.
    pub fn with(mut self, key: &str, value: &str) -> Variant {
        self.options.insert(key.to_owned(), value.to_owned());
        self
    }

    /// Parses `method+key=value+key=value`. A value may itself contain `=` (the first `=`
    /// separates key and value); keys may not repeat.
    pub fn parse(text: &str) -> Result<Variant, BenchError> {
        let mut parts = text.trim().split('+');
        let method = parts.next().unwrap_or_default().trim();
        if method.is_empty()
            || !method
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(BenchError::Usage(format!(
                "variant {text:?}: expected a method name like `nesycr` or `nesycr+verification=off`"
            )));
        }
        let mut options = BTreeMap::new();
        for part in parts {
            let Some((key, value)) = part.split_once('=') else {
                return Err(BenchError::Usage(format!(
                    "variant {text:?}: setting {part:?} needs the form key=value"
                )));
            };
            let key = key.trim();
            if key.is_empty() || options.insert(key.to_owned(), value.trim().to_owned()).is_some() {
                return Err(BenchError::Usage(format!(
                    "variant {text:?}: setting {key:?} is empty or given twice"
                )));
            }
        }
        Ok(Variant {
            method: method.to_owned(),
            options,
        })
    }

    /// A setting's value.
    pub fn option(&self, key: &str) -> Option<&str> {
        self.options.get(key).map(String::as_str)
    }

    /// The variant's id: `method` or `method+key=value…` with keys sorted. It names the
    /// variant in records, folders and tables.
    pub fn id(&self) -> String {
        let mut id = self.method.clone();
        for (k, v) in &self.options {
            id.push('+');
            id.push_str(k);
            id.push('=');
            id.push_str(v);
        }
        id
    }

    /// The id made safe for a file name (`+` and `=` kept, other unusual characters as `_`).
    pub fn file_name(&self) -> String {
        self.id()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "+=-_.".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    }
}

impl fmt::Display for Variant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.id())
    }
}

/// SHA-256 (hex) of a value's canonical JSON (object keys sorted by serde_json's map, which
/// is a BTreeMap here): the configuration hash of anything serialisable.
pub(crate) fn config_hash(value: &impl Serialize) -> String {
    let canonical = serde_json::to_value(value)
        .map(|v| v.to_string())
        .unwrap_or_default();
    hex(&Sha256::digest(canonical.as_bytes()))
}

/// Lower-case hex of bytes.
pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The noise knobs of a variant's `noise` setting (`;` or `,` between knobs).
pub(crate) fn noise_of(spec: &str) -> Result<nesy_oracle::OracleNoise, BenchError> {
    spec.replace(';', ",")
        .parse()
        .map_err(|e| BenchError::Usage(format!("noise={spec:?}: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_canonical() {
        let v = Variant::parse("nesycr+verification=off+on-unresolved=compile-last").unwrap();
        assert_eq!(v.method, "nesycr");
        assert_eq!(v.id(), "nesycr+on-unresolved=compile-last+verification=off");
        assert_eq!(Variant::parse(&v.id()).unwrap(), v);
        let noisy = Variant::parse("nesycr+noise=op-drop=0.1;op-flip=0.05").unwrap();
        assert_eq!(noisy.option("noise"), Some("op-drop=0.1;op-flip=0.05"));
        assert!(Variant::parse("").is_err());
        assert!(Variant::parse("nesycr+bad").is_err());
        assert!(Variant::parse("nesycr+a=1+a=2").is_err());
    }
}
