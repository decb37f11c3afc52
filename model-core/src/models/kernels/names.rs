//! Parameter names of const-generic models, built at compile time: `name[N]` block names for
//! [`Model::PARAM_NAMES`](crate::Model::PARAM_NAMES) (operator, network and NARX models).

/// Generates `["name[0]", "name[1]", …, "name[64]"]` for block parameter names.
macro_rules! block_names {
    ($name:literal) => {
        $crate::models::kernels::names::block_names!(@ $name;
            0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30
            31 32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57 58
            59 60 61 62 63 64)
    };
    (@ $name:literal; $($n:literal)*) => {
        [$(concat!($name, "[", $n, "]")),*]
    };
}
pub(crate) use block_names;

/// Entry `n` of a name table in a const context (`"?"` past its end).
pub(crate) const fn pick(mut table: &'static [&'static str], mut n: usize) -> &'static str {
    while let [first, rest @ ..] = table {
        if n == 0 {
            return first;
        }
        n -= 1;
        table = rest;
    }
    "?"
}

/// A block name `base[len]` built at compile time (for const-generic `PARAM_NAMES`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockName {
    buf: [u8; 32],
    len: usize,
}

impl BlockName {
    /// `base` (≤ 20 ASCII bytes) followed by `[len]`.
    ///
    /// Used only to initialise associated constants, i.e. evaluated by the compiler. The
    /// indices stay in bounds by construction (≤ 20 + 1 + 10 + 1 = 32 bytes), and in const
    /// evaluation an out-of-bounds index would be a compile error, not a run-time panic.
    #[allow(clippy::indexing_slicing)]
    pub(crate) const fn new(base: &str, n: usize) -> Self {
        let mut buf = [0u8; 32];
        let b = base.as_bytes();
        let mut i = 0;
        while i < b.len() && i < 20 {
            buf[i] = b[i];
            i += 1;
        }
        buf[i] = b'[';
        i += 1;
        let mut digits = [0u8; 10];
        let mut nd = 0;
        let mut v = n;
        loop {
            digits[nd] = b'0' + (v % 10) as u8;
            nd += 1;
            v /= 10;
            if v == 0 || nd == digits.len() {
                break;
            }
        }
        while nd > 0 {
            nd -= 1;
            buf[i] = digits[nd];
            i += 1;
        }
        buf[i] = b']';
        i += 1;
        Self { buf, len: i }
    }

    pub(crate) const fn as_str(&'static self) -> &'static str {
        let (head, _) = self.buf.split_at(self.len);
        match core::str::from_utf8(head) {
            Ok(s) => s,
            Err(_) => "?",
        }
    }
}
