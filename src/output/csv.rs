//! Tables as CSV text, for the bench's and the accuracy study's results.

use serde::Serialize;

/// `rows` as CSV: a header of the field names, then a line per row.
pub fn csv_text<T: Serialize>(rows: &[T]) -> String {
    let mut writer = csv::Writer::from_writer(vec![]);
    for row in rows {
        writer
            .serialize(row)
            .expect("plain records serialise to CSV in memory");
    }
    let bytes = writer.into_inner().expect("writing to memory cannot fail");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
}
