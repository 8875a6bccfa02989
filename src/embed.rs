//! Data embedded in the HTML pages formation writes (the review page of `track` and
//! `annotate`, the report): JSON inside a `<script>` element and text inside elements.
//!
//! Inside `<script>`, an HTML parser ends the element at the first `</script` and treats
//! `<!--` followed later by `<script` as the start of an "escaped" run in which even
//! `</script>` no longer closes it. A name such as `<!--<script>` in a directory or a source
//! therefore merged the page's two scripts into one and its code never ran. [`script_json`]
//! writes JSON with every `<`, `>` and `&` as a `\u` escape (and the line separators U+2028,
//! U+2029, which older JavaScript parsers refuse in strings), so the element's text holds no
//! `<` at all and parses back to the same value. [`script_texts`] is the HTML standard's
//! tokenizer for script elements, used by the tests and the fuzz target to check that a page
//! parses into the elements it was written with.

/// `value` as JSON safe inside a `<script>` element: no `<`, `>` or `&` anywhere in the text.
pub fn script_json(value: &serde_json::Value) -> String {
    script_json_text(&value.to_string())
}

/// JSON text (as `serde_json` writes it) made safe inside a `<script>` element the same way as
/// [`script_json`]: every `<`, `>` and `&` (which JSON has only inside strings) as a `\u` escape.
pub fn script_json_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        match c {
            // Outside strings JSON has none of these, so each is inside a string, where a
            // `\u` escape stands for the same character.
            '<' => out.push_str("\\u003c"),
            '>' => out.push_str("\\u003e"),
            '&' => out.push_str("\\u0026"),
            '\u{2028}' => out.push_str("\\u2028"),
            '\u{2029}' => out.push_str("\\u2029"),
            c => out.push(c),
        }
    }
    out
}

/// `s` as HTML text or attribute value: `&`, `<`, `>`, `"` and `'` as character references.
pub fn html_text(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

fn starts_with_ci(s: &[u8], at: usize, word: &[u8]) -> bool {
    s.len() >= at + word.len() && s[at..at + word.len()].eq_ignore_ascii_case(word)
}

fn is_tag_end(b: Option<&u8>) -> bool {
    matches!(
        b,
        Some(b' ' | b'\t' | b'\n' | b'\x0c' | b'\r' | b'/' | b'>')
    )
}

/// The text of every `<script>` element of `html` as an HTML parser splits it: the data
/// states of the HTML standard's tokenizer for script elements (plain, escaped after `<!--`,
/// double-escaped after `<!--<script`), where only `</script` followed by a space, `/` or `>`
/// outside the double-escaped state ends the element. Comments outside scripts are skipped;
/// the rest of the markup is only scanned for `<script` start tags. A page whose scripts are
/// intact gives as many texts as it has `<script` tags written.
pub fn script_texts(html: &str) -> Vec<String> {
    let s = html.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        if starts_with_ci(s, i, b"<!--") {
            // A comment in the markup: up to the next `-->`.
            match html[i + 4..].find("-->") {
                Some(k) => i += 4 + k + 3,
                None => break,
            }
            continue;
        }
        if !(starts_with_ci(s, i, b"<script") && is_tag_end(s.get(i + 7))) {
            i += 1;
            continue;
        }
        // The start tag ends at the next `>` (attribute values here hold none).
        let Some(k) = html[i..].find('>') else { break };
        let start = i + k + 1;
        // 0 plain script data, 1 escaped (after `<!--`), 2 double-escaped (after `<script` in
        // the escaped state).
        let (mut state, mut j) = (0u8, start);
        let end = loop {
            if j >= s.len() {
                break s.len();
            }
            match state {
                0 => {
                    if starts_with_ci(s, j, b"</script") && is_tag_end(s.get(j + 8)) {
                        break j;
                    }
                    if starts_with_ci(s, j, b"<!--") {
                        state = 1;
                        j += 4;
                        continue;
                    }
                }
                1 => {
                    if starts_with_ci(s, j, b"-->") {
                        state = 0;
                        j += 3;
                        continue;
                    }
                    if starts_with_ci(s, j, b"</script") && is_tag_end(s.get(j + 8)) {
                        break j;
                    }
                    if starts_with_ci(s, j, b"<script") && is_tag_end(s.get(j + 7)) {
                        state = 2;
                        j += 7;
                        continue;
                    }
                }
                _ => {
                    if starts_with_ci(s, j, b"-->") {
                        state = 0;
                        j += 3;
                        continue;
                    }
                    if starts_with_ci(s, j, b"</script") && is_tag_end(s.get(j + 8)) {
                        state = 1;
                        j += 8;
                        continue;
                    }
                }
            }
            j += 1;
        };
        out.push(html[start..end].to_string());
        // Past the end tag.
        i = match html[end..].find('>') {
            Some(k) => end + k + 1,
            None => s.len(),
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_strings_stay_inside_their_script() {
        for name in [
            "<!--<script>",
            "</script><script>alert(1)</script>",
            "</SCRIPT >",
            "a\u{2028}b & <b>",
            "<!--",
            "-->",
        ] {
            let v = serde_json::json!({ "name": name, "list": [name, 1] });
            let text = script_json(&v);
            assert!(!text.contains('<') && !text.contains('>'), "{text}");
            let back: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert_eq!(back, v);
            let page = format!(
                "<p>{}</p><script type=\"application/json\">{text}</script>\n<script>go()</script>",
                html_text(name)
            );
            let scripts = script_texts(&page);
            assert_eq!(scripts, vec![text.clone(), "go()".to_string()], "{name}");
        }
    }

    #[test]
    fn the_tokenizer_merges_scripts_as_a_browser_does() {
        // What the old escaping (only `</` → `<\/`) wrote for a source named `<!--<script>`:
        // one element where two were written.
        let page = "<script>{\"s\":\"<!--<script>\"}</script><script>go()</script>";
        assert_eq!(script_texts(page).len(), 1);
        let page = "<script>a</script ><!-- <script>x</script> --><script>b</script>";
        assert_eq!(script_texts(page), vec!["a", "b"]);
    }
}
