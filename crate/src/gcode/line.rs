//! Parsing one line of G-code into a command and its words, borrowing from the input.
//!
//! The grammar is the union of what Marlin, Klipper, RepRapFirmware and the slicers emit:
//! `N` line numbers and `*` checksums, `;` and `( )` comments, upper or lower case, words with or
//! without spaces (`G1X10Y5`), leading-dot numbers (`E.5`), exponents, Klipper extended commands
//! (`SET_VELOCITY_LIMIT ACCEL=3000`) and free-text M-codes (`M117 Printing...`). Nothing here
//! allocates.

use crate::error::ErrorKind;

/// A `G`, `M` or `T` command code such as `G1`, `M204` or `G29.1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Code {
    /// `b'G'`, `b'M'` or `b'T'`.
    pub letter: u8,
    /// The integer part (`1` of `G1`).
    pub number: u16,
    /// The sub-code after a dot (`1` of `G29.1`), if any.
    pub sub: Option<u8>,
}

impl Code {
    /// Whether this is `letter` `number` with no sub-code.
    #[inline]
    pub fn is(&self, letter: u8, number: u16) -> bool {
        self.letter == letter && self.number == number && self.sub.is_none()
    }

    /// Whether this is a motion command: `G0`, `G1`, `G2` or `G3`, with no sub-code.
    #[inline]
    pub fn is_motion(&self) -> bool {
        self.letter == b'G' && self.number <= 3 && self.sub.is_none()
    }
}

/// Numeric words of a line, indexed by letter. Fixed size: parsing a line never allocates.
#[derive(Clone, Copy, PartialEq)]
pub struct Params {
    present: u32,
    bare: u32,
    values: [f64; 26],
}

impl std::fmt::Debug for Params {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut m = f.debug_map();
        for i in 0..26u8 {
            if self.present & (1 << i) != 0 {
                m.entry(&((b'A' + i) as char), &self.values[i as usize]);
            }
        }
        m.finish()
    }
}

impl Params {
    /// Sets word `letter` (either case) to `value`: for a writer that hands a machine the
    /// words a line of its text would parse to, without printing and parsing them.
    #[inline]
    pub fn set(&mut self, letter: u8, value: f64) {
        if let Some(i) = slot(letter) {
            self.present |= 1 << i;
            self.bare &= !(1 << i);
            self.values[i] = value;
        }
    }

    /// Removes every word (values are left in place but no longer visible).
    #[inline]
    pub fn clear(&mut self) {
        self.present = 0;
        self.bare = 0;
    }
}

impl Default for Params {
    fn default() -> Self {
        Self {
            present: 0,
            bare: 0,
            values: [0.0; 26],
        }
    }
}

#[inline]
fn slot(letter: u8) -> Option<usize> {
    let up = letter.to_ascii_uppercase();
    up.is_ascii_uppercase().then(|| (up - b'A') as usize)
}

impl Params {
    /// The value of word `letter` (either case), if present with a number.
    #[inline]
    pub fn get(&self, letter: u8) -> Option<f64> {
        let i = slot(letter)?;
        (self.present & (1 << i) != 0 && self.bare & (1 << i) == 0).then(|| self.values[i])
    }

    /// Whether word `letter` appears at all, with or without a number (`G28 X`).
    #[inline]
    pub fn has(&self, letter: u8) -> bool {
        slot(letter).is_some_and(|i| self.present & (1 << i) != 0)
    }

    /// Whether some word has no number (`G28 X`).
    #[inline]
    pub fn has_bare_word(&self) -> bool {
        self.bare != 0
    }

    /// The words that have a number, as a bit set: bit `i` for letter `b'A' + i`.
    #[inline]
    pub fn numbered(&self) -> u32 {
        self.present & !self.bare
    }

    /// The words among `letters` (a bit set like [`Params::numbered`]) that have a number,
    /// with their values, in alphabetical order.
    #[inline]
    pub fn numbers_in(&self, letters: u32) -> impl Iterator<Item = (u8, f64)> + '_ {
        let mut bits = self.numbered() & letters;
        std::iter::from_fn(move || {
            (bits != 0).then(|| {
                let i = bits.trailing_zeros();
                bits &= bits - 1;
                (b'A' + i as u8, self.values[i as usize])
            })
        })
    }

    /// Whether the line has no words.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.present == 0
    }

    /// The present letters in alphabetical order with their values (`None` for bare words).
    pub fn iter(&self) -> impl Iterator<Item = (u8, Option<f64>)> + '_ {
        (0..26u8).filter_map(move |i| {
            let bit = 1u32 << i;
            (self.present & bit != 0).then(|| {
                (
                    b'A' + i,
                    (self.bare & bit == 0).then(|| self.values[i as usize]),
                )
            })
        })
    }

    /// Whether the word at `slot` (0 for `A`) is present.
    #[inline]
    fn has_slot(&self, slot: u8) -> bool {
        self.present & (1 << slot) != 0
    }

    /// Sets the word at `slot` (0 for `A`) to `v`.
    #[inline]
    fn insert_value(&mut self, slot: u8, v: f64) {
        let bit = 1u32 << slot;
        self.present |= bit;
        self.bare &= !bit;
        self.values[usize::from(slot)] = v;
    }

    fn insert(&mut self, letter: u8, value: Option<f64>) -> bool {
        let Some(i) = slot(letter) else { return true };
        let bit = 1u32 << i;
        let fresh = self.present & bit == 0;
        self.present |= bit;
        match value {
            Some(v) => {
                self.values[i] = v;
                self.bare &= !bit;
            }
            None => self.bare |= bit,
        }
        fresh
    }
}

/// The command of a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Command<'a> {
    /// Blank line or comment only.
    #[default]
    None,
    /// `G`, `M` or `T` code.
    Code(Code),
    /// Klipper-style extended command (`SET_VELOCITY_LIMIT`, `EXCLUDE_OBJECT_START`, a macro
    /// name like `PRINT_START`), as written (case kept).
    Extended(&'a [u8]),
    /// Words with no command letter first (`X10 Y5`), kept as parameters.
    Bare,
}

/// One parsed line, borrowing from the input.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Line<'a> {
    /// The command.
    pub command: Command<'a>,
    /// Numeric words, except the command itself.
    pub params: Params,
    /// Free text: the message of `M117`-like commands, or the arguments of an extended command
    /// (`ACCEL=3000 ACCEL_TO_DECEL=1500`), trimmed.
    pub text: &'a [u8],
    /// The text after the first `;`, or inside the first `( )` if there is no `;`.
    pub comment: Option<&'a [u8]>,
    /// `N` line number, if the line has one.
    pub line_number: Option<i64>,
    /// `*` checksum as written, if the line has one.
    pub checksum: Option<u32>,
}

impl<'a> Line<'a> {
    /// The `G`/`M`/`T` code, if the command is one.
    #[inline]
    pub fn code(&self) -> Option<Code> {
        match self.command {
            Command::Code(c) => Some(c),
            _ => None,
        }
    }

    /// The value of `KEY=value` in an extended command's arguments (key matched without case).
    pub fn extended_arg(&self, key: &str) -> Option<&'a [u8]> {
        extended_arg(self.text, key)
    }
}

/// Looks up `KEY=value` in Klipper-style arguments; the key is matched without case.
pub fn extended_arg<'a>(args: &'a [u8], key: &str) -> Option<&'a [u8]> {
    args.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .find_map(|tok| {
            let eq = tok.iter().position(|&b| b == b'=')?;
            tok[..eq]
                .eq_ignore_ascii_case(key.as_bytes())
                .then(|| &tok[eq + 1..])
        })
}

/// A parse failure inside a line: column (1-based) and kind.
#[derive(Debug, Clone, PartialEq)]
pub struct LineError {
    /// 1-based column.
    pub column: u32,
    /// What went wrong.
    pub kind: ErrorKind,
}

/// Most bytes of a line's command part (before any comment) that the parser accepts. Comments
/// may be of any length (thumbnails, settings blocks), commands may not: a 20 MB command line is
/// corruption, and rejecting it keeps the cost of a hostile line bounded.
pub const MAX_COMMAND_BYTES: usize = 64 * 1024;

/// M-codes whose parameters are free text (the whole rest of the line up to a comment).
fn takes_text(code: Code) -> bool {
    code.letter == b'M'
        && matches!(
            code.number,
            23 | 28 | 30 | 32 | 36 | 117 | 118 | 550 | 551 | 552 | 587 | 589 | 1117
        )
}

#[inline]
fn is_space(b: u8) -> bool {
    b == b' ' || b == b'\t' || b == b'\r' || b == 0x0b || b == 0x0c
}

fn trim(mut s: &[u8]) -> &[u8] {
    while let [first, rest @ ..] = s {
        if is_space(*first) {
            s = rest;
        } else {
            break;
        }
    }
    while let [rest @ .., last] = s {
        if is_space(*last) {
            s = rest;
        } else {
            break;
        }
    }
    s
}

/// Scans the numeric token at the start of `s`: `[+-] digits [. digits] [exponent]`, returning
/// its length (0 if there is no number).
///
/// Exponents: Marlin never reads `E` as an exponent (`G1X10E-2` is X=10 and a 2 mm retraction),
/// and neither do we for an upper-case `E`. A lower-case `e` after an upper-case word letter
/// (`X1e3`, `Y2e-5`) can only be an exponent, since no all-caps dialect writes a lower-case
/// extrusion word, so that one is read as an exponent; in all-lower-case lines (`g1x10e-2`) `e`
/// is the extrusion word again.
#[inline]
pub(crate) fn scan_number(s: &[u8], upper_letter: bool) -> usize {
    let mut i = 0;
    if matches!(s.first(), Some(b'+' | b'-')) {
        i = 1;
    }
    let int_start = i;
    while i < s.len() && s[i].is_ascii_digit() {
        i += 1;
    }
    let mut digits = i - int_start;
    if i < s.len() && s[i] == b'.' {
        i += 1;
        let frac_start = i;
        while i < s.len() && s[i].is_ascii_digit() {
            i += 1;
        }
        digits += i - frac_start;
    }
    if digits == 0 {
        return 0;
    }
    if upper_letter && i + 1 < s.len() && s[i] == b'e' {
        let next = s[i + 1];
        let signed = (next == b'+' || next == b'-') && s.get(i + 2).is_some_and(u8::is_ascii_digit);
        if signed || next.is_ascii_digit() {
            i += if signed { 2 } else { 1 };
            while i < s.len() && s[i].is_ascii_digit() {
                i += 1;
            }
        }
    }

    i
}

/// `inf`, `nan`, `infinity` (any case, optional sign) where a number belongs.
fn spells_non_finite(s: &[u8]) -> bool {
    let s = match s.first() {
        Some(b'+' | b'-') => &s[1..],
        _ => s,
    };
    s.get(..3)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"inf") || w.eq_ignore_ascii_case(b"nan"))
}

/// Exact powers of ten representable in an `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Scans and converts the number at the start of `s` (see [`scan_number`] for the grammar),
/// returning its length (0 if none) and value.
///
/// G-code numbers are short decimals (`123.456`), so the digits are accumulated while scanning
/// and converted with Clinger's fast path: a mantissa below 2^53 times or divided by an exact
/// power of ten up to 10^22 is correctly rounded by one IEEE operation. Anything longer (or with
/// an exponent) goes to the general correctly-rounded parser, so results never differ from it.
#[inline]
fn parse_number(s: &[u8], upper_letter: bool) -> (usize, Option<f64>) {
    let mut i = 0;
    let negative = match s.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    let mut mantissa: u64 = 0;
    let mut digits = 0usize;
    while i < s.len() && s[i].is_ascii_digit() {
        mantissa = mantissa
            .wrapping_mul(10)
            .wrapping_add(u64::from(s[i] - b'0'));
        digits += 1;
        i += 1;
    }
    let mut frac_digits = 0usize;
    if i < s.len() && s[i] == b'.' {
        i += 1;
        while i < s.len() && s[i].is_ascii_digit() {
            mantissa = mantissa
                .wrapping_mul(10)
                .wrapping_add(u64::from(s[i] - b'0'));
            frac_digits += 1;
            i += 1;
        }
    }
    if digits + frac_digits == 0 {
        return (0, None);
    }
    let has_exponent = upper_letter && i + 1 < s.len() && s[i] == b'e';
    if !has_exponent && digits + frac_digits <= 15 && frac_digits < POW10.len() {
        let v = mantissa as f64 / POW10[frac_digits];
        return (i, Some(if negative { -v } else { v }));
    }
    let len = scan_number(s, upper_letter);
    (len, parse_f64(&s[..len]))
}

/// Parses the line at the start of `rest` (the input from the line's first byte to its end)
/// if it is a plain G-code line: `G` and a number of at most four digits, then plain words
/// (see [`plain_words`]) and spaces up to the newline or the end of the input. Returns where
/// it stopped (the newline, or the end of `rest`), having filled `line` exactly as
/// [`parse_line_into`] fills it for that line's text; `None` for any other line (a comment,
/// anything unusual, or a duplicate word, which the general parser reports), with `line` to
/// be parsed again.
///
/// Such lines are nearly all of a slicer's file, and this finds a line's end and parses it in
/// one pass instead of a search for the newline, one for a comment and the parse.
pub(crate) fn parse_plain_line<'a>(rest: &'a [u8], line: &mut Line<'a>) -> Option<usize> {
    if rest.first() != Some(&b'G') {
        return None;
    }
    let mut pos = 1;
    let mut number: u16 = 0;
    while let Some(d) = rest
        .get(pos)
        .map(|c| c.wrapping_sub(b'0'))
        .filter(|d| *d <= 9)
    {
        if pos > 4 {
            return None;
        }
        number = number * 10 + u16::from(d);
        pos += 1;
    }
    if pos == 1 {
        return None;
    }
    line.params.clear();
    loop {
        while rest.get(pos).is_some_and(|&b| is_space(b)) {
            pos += 1;
        }
        let Some(&letter) = rest.get(pos).filter(|&&b| b != b'\n') else {
            break;
        };
        if !letter.is_ascii_uppercase() || pos > MAX_COMMAND_BYTES {
            return None;
        }
        pos = plain_word(rest, pos, &mut line.params, |n| {
            is_space(n) || n.is_ascii_uppercase() || n == b'\n'
        })?;
    }
    line.command = Command::Code(Code {
        letter: b'G',
        number,
        sub: None,
    });
    line.text = &[];
    line.comment = None;
    line.line_number = None;
    line.checksum = None;
    Some(pos)
}

/// Reads the words of a line from `pos` as long as they are plain: an upper-case letter
/// glued to a plain decimal (see [`plain_decimal`]) and followed by a separator, another word
/// or the end, and not already given. Returns where it stopped: the end of `code`, or the first
/// word that is not plain, for the general loop of [`parse_line_into`] to read (it gives the
/// same result for plain words, only slower: nearly every word of a slicer's file is plain).
#[inline]
fn plain_words(code: &[u8], mut pos: usize, params: &mut Params) -> usize {
    loop {
        while code.get(pos).is_some_and(|&b| is_space(b)) {
            pos += 1;
        }
        if !code.get(pos).is_some_and(|b| b.is_ascii_uppercase()) {
            return pos;
        }
        match plain_word(code, pos, params, |n| {
            is_space(n) || n.is_ascii_alphabetic() || n == b'('
        }) {
            Some(after) => pos = after,
            None => return pos,
        }
    }
}

/// Reads the word whose upper-case letter is at `pos` of `s` into `params` if it is plain: a
/// plain decimal glued to the letter (see [`plain_decimal`]), then the end of `s` or a byte
/// for which `ends_word` holds, and no word of that letter yet. Returns where the word ends;
/// `None`, with `params` untouched, for any other word. (The one-pass line reader and the
/// general parser differ only in what may follow a word: a newline, or a comment.)
#[inline(always)]
fn plain_word(
    s: &[u8],
    pos: usize,
    params: &mut Params,
    ends_word: impl Fn(u8) -> bool,
) -> Option<usize> {
    let letter = *s.get(pos)?;
    let (len, v) = plain_decimal(s.get(pos + 1..)?)?;
    let after = pos + 1 + len;
    let slot = letter - b'A';
    if !s.get(after).is_none_or(|&n| ends_word(n)) || params.has_slot(slot) {
        return None;
    }
    params.insert_value(slot, v);
    Some(after)
}

/// The number at the start of `s` if it is a plain decimal, `[+-] digits [. digits]` with at
/// most 15 digits and no exponent after it: its length and value, exactly as [`parse_number`]
/// reads it (Clinger's fast path). `None` for anything else, which [`parse_number`] handles.
#[inline(always)]
fn plain_decimal(s: &[u8]) -> Option<(usize, f64)> {
    let (negative, mut i) = match s.first() {
        Some(b'-') => (true, 1),
        Some(b'+') => (false, 1),
        _ => (false, 0),
    };
    let mut mantissa: u64 = 0;
    let mut digits = 0usize;
    while let Some(d) = s.get(i).map(|c| c.wrapping_sub(b'0')).filter(|d| *d <= 9) {
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        digits += 1;
        i += 1;
    }
    let mut frac_digits = 0usize;
    if s.get(i) == Some(&b'.') {
        i += 1;
        while let Some(d) = s.get(i).map(|c| c.wrapping_sub(b'0')).filter(|d| *d <= 9) {
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
            frac_digits += 1;
            i += 1;
        }
    }
    if digits + frac_digits == 0 || digits + frac_digits > 15 || s.get(i) == Some(&b'e') {
        return None;
    }
    let v = mantissa as f64 / POW10[frac_digits];
    Some((i, if negative { -v } else { v }))
}

#[inline]
fn parse_f64(token: &[u8]) -> Option<f64> {
    let token = token.strip_prefix(b"+").unwrap_or(token);
    fast_float2::parse::<f64, _>(token).ok()
}

/// XOR checksum as Marlin and RepRap hosts compute it: every byte before `*`.
pub fn checksum(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0u8, |acc, b| acc ^ b)
}

/// Parses one line (without its terminator).
///
/// `strict_numbers` applies to G-code words: in an M-code, a word whose value is not a number
/// (`M486 AObject`, RepRapFirmware's `P"text"`) is skipped, because firmware treats such values
/// as strings.
pub fn parse_line(text: &[u8]) -> Result<Line<'_>, LineError> {
    let mut line = Line::default();
    parse_line_into(text, &mut line)?;
    Ok(line)
}

/// [`parse_line`] into an existing [`Line`], which is reset first. Reusing one `Line` for a
/// whole file avoids initialising and moving its word table for every line.
pub fn parse_line_into<'a>(text: &'a [u8], line: &mut Line<'a>) -> Result<(), LineError> {
    line.command = Command::None;
    line.params.clear();
    line.text = &[];
    line.comment = None;
    line.line_number = None;
    line.checksum = None;

    // Comment: everything after the first ';' (a ';' never appears inside a command).
    let mut end = match memchr::memchr(b';', text) {
        Some(p) => {
            line.comment = Some(&text[p + 1..]);
            p
        }
        None => text.len(),
    };
    if end > MAX_COMMAND_BYTES {
        let max = MAX_COMMAND_BYTES;
        return Err(error_at(max, ErrorKind::LineTooLong { max }));
    }
    // UTF-8 byte-order mark at the start of a file.
    let bom = if text.starts_with(&[0xEF, 0xBB, 0xBF]) {
        3
    } else {
        0
    };
    let mut pos = skip_spaces(text, bom, end);
    // `%` marks program start/end in CNC-style files; nothing else may follow it.
    if pos >= end || text[pos] == b'%' {
        return Ok(());
    }
    if matches!(text[pos], b'N' | b'n') {
        if let Some((star, found)) = checksum_of(text, end)? {
            line.checksum = Some(found);
            end = star;
        }
        pos = line_number(text, pos, end, line);
        if pos >= end {
            return Ok(());
        }
    }
    match command(text, pos, end, line)? {
        Some((pos, is_g)) => words(text, pos, end, is_g, line),
        None => Ok(()),
    }
}

/// A [`LineError`] at byte `pos` of the line (its column is `pos + 1`).
fn error_at(pos: usize, kind: ErrorKind) -> LineError {
    LineError {
        column: u32::try_from(pos + 1).unwrap_or(u32::MAX),
        kind,
    }
}

/// The first byte at or after `pos` (before `end`) that is not blank ([`is_space`]: space,
/// tab, CR, VT or FF).
#[inline]
fn skip_spaces(text: &[u8], mut pos: usize, end: usize) -> usize {
    while pos < end && is_space(text[pos]) {
        pos += 1;
    }
    pos
}

/// The checksum `*nn` at the end of a numbered line's command part `text[..end]`: where its
/// `*` is and the value, checked against the line. The host protocol puts checksums only on
/// numbered lines (`N123 ... *nn`), so only those are searched for one.
fn checksum_of(text: &[u8], end: usize) -> Result<Option<(usize, u32)>, LineError> {
    let Some(star) = memchr::memrchr(b'*', &text[..end]) else {
        return Ok(None);
    };
    let digits = trim(&text[star + 1..end]);
    if digits.is_empty() || !digits.iter().all(u8::is_ascii_digit) || digits.len() > 9 {
        return Ok(None);
    }
    let found = digits
        .iter()
        .fold(0u32, |a, d| a * 10 + u32::from(d - b'0'));
    let computed = checksum(&text[..star]);
    if found != u32::from(computed) {
        return Err(error_at(
            star,
            ErrorKind::ChecksumMismatch { found, computed },
        ));
    }
    Ok(Some((star, found)))
}

/// The `N` line number at `pos`, if there is one, into `line`; where the command starts.
fn line_number(text: &[u8], pos: usize, end: usize, line: &mut Line<'_>) -> usize {
    let numbered = text
        .get(pos + 1)
        .is_some_and(|b| b.is_ascii_digit() || *b == b'-');
    if !numbered {
        return pos;
    }
    let len = scan_number(&text[pos + 1..end], true);
    let n = parse_f64(&text[pos + 1..pos + 1 + len]).unwrap_or(0.0);
    line.line_number = Some(n as i64);
    skip_spaces(text, pos + 1 + len, end)
}

/// The command at `pos` into `line`: where its words start and whether they are a G-code's
/// (strictly checked), or `None` where the line has no words to read (a Klipper extended
/// command or a message, whose text is kept as it is).
fn command<'a>(
    text: &'a [u8],
    pos: usize,
    end: usize,
    line: &mut Line<'a>,
) -> Result<Option<(usize, bool)>, LineError> {
    let first = text[pos];
    let second = text.get(pos + 1).copied().unwrap_or(b' ');
    if first.is_ascii_alphabetic() && (second.is_ascii_alphabetic() || second == b'_') {
        // Klipper extended command / macro: NAME args...
        let name_end = text[pos..end]
            .iter()
            .position(|&b| is_space(b))
            .map_or(end, |p| pos + p);
        line.command = Command::Extended(&text[pos..name_end]);
        line.text = trim(&text[name_end..end]);
        return Ok(None);
    }
    let up = first.to_ascii_uppercase();
    if matches!(up, b'G' | b'M' | b'T') && second.is_ascii_digit() {
        let (code, after) = code_at(text, pos + 1, end, up);
        line.command = Command::Code(code);
        if takes_text(code) {
            // The message starts after one separating space; keep the rest verbatim.
            line.text = trim(&text[after..end]);
            return Ok(None);
        }
        return Ok(Some((after, up == b'G')));
    }
    if first.is_ascii_alphabetic() {
        line.command = Command::Bare;
        return Ok(Some((pos, true)));
    }
    if first == b'(' {
        return Ok(Some((pos, false)));
    }
    let found = display_char(first);
    Err(error_at(pos, ErrorKind::UnexpectedCharacter { found }))
}

/// The code `letter` whose digits start at `i` (`G1`, `M486`, `G38.2`), and where it ends.
fn code_at(text: &[u8], mut i: usize, end: usize, letter: u8) -> (Code, usize) {
    let digits = |i: &mut usize| {
        let mut n: u32 = 0;
        while *i < end && text[*i].is_ascii_digit() {
            n = n
                .saturating_mul(10)
                .saturating_add(u32::from(text[*i] - b'0'));
            *i += 1;
        }
        n
    };
    let number = digits(&mut i);
    let mut sub = None;
    if i + 1 < end && text[i] == b'.' && text[i + 1].is_ascii_digit() {
        i += 1;
        sub = Some(u8::try_from(digits(&mut i)).unwrap_or(u8::MAX));
    }
    let code = Code {
        letter,
        number: u16::try_from(number).unwrap_or(u16::MAX),
        sub,
    };
    (code, i)
}

/// The words of the command part `text[..end]` from `pos` into `line.params`: the plain ones
/// at once ([`plain_words`]), the rest one by one with comments in brackets between them. In a
/// G-code (`is_g`) anything else is an error; in an M-code a token that is no word is a string
/// argument, and skipped.
fn words<'a>(
    text: &'a [u8],
    pos: usize,
    end: usize,
    is_g: bool,
    line: &mut Line<'a>,
) -> Result<(), LineError> {
    let mut pos = plain_words(&text[..end], pos, &mut line.params);
    while pos < end {
        let b = text[pos];
        if is_space(b) {
            pos += 1;
        } else if b == b'(' {
            let close = memchr::memchr(b')', &text[pos..end])
                .ok_or_else(|| error_at(pos, ErrorKind::UnclosedComment))?;
            if line.comment.is_none() {
                line.comment = Some(&text[pos + 1..pos + close]);
            }
            pos += close + 1;
        } else if b.is_ascii_alphabetic() {
            pos = word(text, pos, end, is_g, &mut line.params)?;
        } else if is_g {
            let found = display_char(b);
            return Err(error_at(pos, ErrorKind::UnexpectedCharacter { found }));
        } else {
            // Inside an M-code's string argument: skip the token.
            pos = skip_token(text, pos, end);
        }
    }
    Ok(())
}

/// The first space or tab at or after `pos` (before `end`).
fn skip_token(text: &[u8], mut pos: usize, end: usize) -> usize {
    while pos < end && !is_space(text[pos]) {
        pos += 1;
    }
    pos
}

/// The word whose letter is at `letter_pos`, into `params`; where the next token starts.
fn word(
    text: &[u8],
    letter_pos: usize,
    end: usize,
    is_g: bool,
    params: &mut Params,
) -> Result<usize, LineError> {
    let b = text[letter_pos];
    let letter = b.to_ascii_uppercase();
    // Only spaces and tabs between a letter and its number (`X 10`).
    let mut vpos = letter_pos + 1;
    while vpos < end && (text[vpos] == b' ' || text[vpos] == b'\t') {
        vpos += 1;
    }
    let number = word_value(text, vpos, end, b.is_ascii_uppercase(), letter as char)?;
    let pos = number.map_or(letter_pos + 1, |(_, len)| vpos + len);
    let value = number.map(|(v, _)| v);
    // What follows a word must be a separator, another word or a comment.
    let next = text.get(pos).copied().filter(|_| pos < end);
    // In a G-code, a letter glued to a word that has no number (`Xabc`) is a typo, not two
    // words; bare words must be separated (`G28 X Y`).
    let clean_end = match next {
        None => true,
        Some(n) if n.is_ascii_alphabetic() => value.is_some() || !is_g,
        Some(n) => is_space(n) || n == b'(',
    };
    if !clean_end {
        if !is_g {
            return Ok(skip_token(text, pos, end));
        }
        let glued = next.is_some_and(|n| n.is_ascii_alphanumeric() || n == b'.');
        let kind = if glued || value.is_none() {
            ErrorKind::InvalidNumber {
                letter: letter as char,
            }
        } else {
            ErrorKind::UnexpectedCharacter {
                found: display_char(next.unwrap_or(b'?')),
            }
        };
        return Err(error_at(if value.is_some() { pos } else { vpos }, kind));
    }
    if !params.insert(letter, value) && is_g {
        let letter = letter as char;
        return Err(error_at(letter_pos, ErrorKind::DuplicateWord { letter }));
    }
    Ok(pos)
}

/// The number of the word `letter` starting at `vpos` and its length in bytes, `None` where
/// none follows the letter; a number that does not parse or is not finite is an error.
fn word_value(
    text: &[u8],
    vpos: usize,
    end: usize,
    upper_letter: bool,
    letter: char,
) -> Result<Option<(f64, usize)>, LineError> {
    let (len, parsed) = parse_number(&text[vpos..end], upper_letter);
    if len == 0 {
        if spells_non_finite(&text[vpos..end]) {
            return Err(error_at(vpos, ErrorKind::NonFiniteNumber { letter }));
        }
        return Ok(None);
    }
    let v = parsed.ok_or_else(|| error_at(vpos, ErrorKind::InvalidNumber { letter }))?;
    if !v.is_finite() {
        return Err(error_at(vpos, ErrorKind::NonFiniteNumber { letter }));
    }
    Ok(Some((v, len)))
}

fn display_char(b: u8) -> char {
    if b.is_ascii() {
        b as char
    } else {
        char::REPLACEMENT_CHARACTER
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(s: &str) -> Line<'_> {
        parse_line(s.as_bytes()).unwrap_or_else(|e| panic!("{s:?}: {e:?}"))
    }

    fn g(n: u16) -> Command<'static> {
        Command::Code(Code {
            letter: b'G',
            number: n,
            sub: None,
        })
    }

    #[test]
    fn basic_move() {
        let l = ok("G1 X10.5 Y-2 E.5 F1800 ; infill");
        assert_eq!(l.command, g(1));
        assert_eq!(l.params.get(b'X'), Some(10.5));
        assert_eq!(l.params.get(b'Y'), Some(-2.0));
        assert_eq!(l.params.get(b'E'), Some(0.5));
        assert_eq!(l.params.get(b'F'), Some(1800.0));
        assert_eq!(l.params.get(b'Z'), None);
        assert_eq!(l.comment, Some(&b" infill"[..]));
    }

    #[test]
    fn compact_lower_case_and_leading_zero_codes() {
        let l = ok("g01x1y2z.3");
        assert_eq!(l.command, g(1));
        assert_eq!(l.params.get(b'x'), Some(1.0));
        assert_eq!(l.params.get(b'Z'), Some(0.3));
    }

    #[test]
    fn exponents_versus_marlin_e_words() {
        let l = ok("G1 X1E5");
        assert_eq!(l.params.get(b'X'), Some(1.0));
        assert_eq!(l.params.get(b'E'), Some(5.0));
        let l = ok("G1 X1e3 Y2e-2 Z+3");
        assert_eq!(l.params.get(b'X'), Some(1000.0));
        assert_eq!(l.params.get(b'Y'), Some(0.02));
        assert_eq!(l.params.get(b'Z'), Some(3.0));
        // Marlin's reading: an upper-case E after a number is always the extrusion word.
        let l = ok("G1X10E-2");
        assert_eq!(l.params.get(b'X'), Some(10.0));
        assert_eq!(l.params.get(b'E'), Some(-2.0));
        let l = ok("g1x10e-2");
        assert_eq!(l.params.get(b'E'), Some(-2.0));
    }

    #[test]
    fn non_finite_and_bad_numbers_are_errors() {
        let e = parse_line(b"G1 X1e999").unwrap_err();
        assert!(matches!(e.kind, ErrorKind::NonFiniteNumber { letter: 'X' }));
        assert_eq!(e.column, 5);
        assert!(parse_line(b"G1 Xnan").is_err());
        assert!(parse_line(b"G1 Xinf").is_err());
        assert!(parse_line(b"G1 X1.2.3").is_err());
        assert!(parse_line(b"G1 X- Y1").is_err());
        assert!(parse_line(b"G1 X1 X2").is_err());
        assert!(parse_line(b"G1 Xabc Y10").is_err());
        assert!(parse_line(b"G1 X10 Yabc").is_err());
        assert!(parse_line(b"G28 X Y").is_ok());
    }

    #[test]
    fn line_numbers_and_checksums() {
        let body = "N123 G1 X1";
        let cs = checksum(body.as_bytes());
        let text = format!("{body}*{cs}");
        let l = ok(&text);
        assert_eq!(l.line_number, Some(123));
        assert_eq!(l.checksum, Some(u32::from(cs)));
        assert_eq!(l.params.get(b'X'), Some(1.0));
        let bad = format!("{body}*{}", cs.wrapping_add(1));
        let e = parse_line(bad.as_bytes()).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::ChecksumMismatch { .. }));
    }

    #[test]
    fn paren_comments() {
        let l = ok("G0 (rapid) X5 (to five)");
        assert_eq!(l.comment, Some(&b"rapid"[..]));
        assert_eq!(l.params.get(b'X'), Some(5.0));
        assert!(matches!(
            parse_line(b"G0 (oops X5").unwrap_err().kind,
            ErrorKind::UnclosedComment
        ));
        let l = ok("(only a comment)");
        assert_eq!(l.command, Command::None);
    }

    #[test]
    fn klipper_extended_commands() {
        let l = ok("SET_VELOCITY_LIMIT ACCEL=3000 ACCEL_TO_DECEL=1500 ; limits");
        assert_eq!(l.command, Command::Extended(b"SET_VELOCITY_LIMIT"));
        assert_eq!(l.extended_arg("accel"), Some(&b"3000"[..]));
        assert_eq!(l.extended_arg("ACCEL_TO_DECEL"), Some(&b"1500"[..]));
        let l = ok("EXCLUDE_OBJECT_START NAME=part_1.stl_id_0");
        assert_eq!(l.extended_arg("NAME"), Some(&b"part_1.stl_id_0"[..]));
        let l = ok("print_start EXTRUDER=210");
        assert_eq!(l.command, Command::Extended(b"print_start"));
    }

    #[test]
    fn free_text_m_codes() {
        let l = ok("M117 Printing G1 X(y) 50%");
        assert_eq!(l.text, b"Printing G1 X(y) 50%");
        assert!(l.params.is_empty());
        let l = ok("M486 S0 AObject_1");
        assert_eq!(l.params.get(b'S'), Some(0.0));
        assert_eq!(l.params.get(b'A'), None);
    }

    #[test]
    fn bare_words_and_subcodes() {
        let l = ok("G28 X Y");
        assert!(l.params.has(b'X') && l.params.get(b'X').is_none());
        let l = ok("G29.1 Z0.1");
        assert_eq!(l.code().map(|c| c.sub), Some(Some(1)));
        assert_eq!(ok("T1").code().map(|c| c.number), Some(1));
    }

    #[test]
    fn blank_and_odd_lines() {
        assert_eq!(ok("").command, Command::None);
        assert_eq!(ok("   \t").command, Command::None);
        assert_eq!(ok("%").command, Command::None);
        assert_eq!(ok("\u{feff}G1 X1").command, g(1));
        assert!(parse_line(b"G1 X1 \x00").is_err());
        assert!(parse_line(b"\xff\xfe").is_err());
    }

    #[test]
    fn huge_command_line_is_rejected_cheaply() {
        let long = format!("G1 {}", "X1 ".repeat(MAX_COMMAND_BYTES));
        assert!(matches!(
            parse_line(long.as_bytes()).unwrap_err().kind,
            ErrorKind::LineTooLong { .. }
        ));
        let comment = format!("; {}", "x".repeat(MAX_COMMAND_BYTES * 2));
        assert!(parse_line(comment.as_bytes()).is_ok());
    }
}
