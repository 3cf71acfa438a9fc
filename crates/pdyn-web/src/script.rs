//! `pdyn kin` and `pdyn dsolve` in the page: a script of command lines, as in
//! `examples/kin/*.sh` and `examples/dsolve/*.sh`, read the way a POSIX shell splits words
//! (blanks, `'…'`, `"…"`, backslash escapes and continuation lines), each line's flags read as
//! the CLI's (`crates/pdyn-cli/src/cli/{kin,dsolve}.rs`: the same names, the same comma lists),
//! computed by the library and printed by `pdyn::report`. An error is located at the word that
//! caused it: its line and column in the script.

use pdyn::dsolve::DsolveInput;
use pdyn::kin::KinInput;
use pdyn::report::notation::Notation;
use pdyn::Error;
use serde_json::{json, Value};

/// A word of a command line and where it starts in the script.
#[derive(Clone, Debug, PartialEq)]
pub struct Word {
    /// The word after quotes and escapes are removed.
    pub text: String,
    /// 1-based line of its first character.
    pub line: usize,
    /// 1-based column (in characters) of its first character.
    pub column: usize,
    /// Columns between the word's start and its text's first character (an opening quote).
    pub quote: usize,
}

/// A command line of the script: its words, and the line it starts on.
#[derive(Debug)]
pub struct CommandLine {
    /// The words, `pdyn` first.
    pub words: Vec<Word>,
    /// The line of the first word.
    pub line: usize,
}

/// An error at a place of the script.
#[derive(Debug)]
pub struct Located {
    /// What went wrong.
    pub error: Box<Error>,
    /// Line and column in the script.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

/// The scripts' longest input: a page's script is typed or pasted, not generated.
const MAX_SCRIPT_BYTES: usize = 1 << 20;

fn located(line: usize, column: usize, message: String) -> Located {
    Located {
        error: Box::new(Error::argument("script", message)),
        line,
        column,
    }
}

/// Splits a script into command lines: `#` comments and blank lines skipped, a trailing
/// backslash continues a line, quotes as in `sh`. An unclosed quote is an error at the quote.
pub fn split(script: &str) -> Result<Vec<CommandLine>, Located> {
    if script.len() > MAX_SCRIPT_BYTES {
        return Err(located(
            1,
            1,
            format!(
                "the script is {} bytes; scripts up to {MAX_SCRIPT_BYTES} bytes are read",
                script.len()
            ),
        ));
    }
    let mut commands = Vec::new();
    let mut words: Vec<Word> = Vec::new();
    let mut current: Option<Word> = None;
    let (mut line, mut column) = (1usize, 0usize);
    let mut chars = script.chars().peekable();
    let finish_word = |current: &mut Option<Word>, words: &mut Vec<Word>| {
        if let Some(w) = current.take() {
            words.push(w);
        }
    };
    let start = |current: &mut Option<Word>, line: usize, column: usize| {
        current.get_or_insert(Word {
            text: String::new(),
            line,
            column,
            quote: 0,
        });
    };
    while let Some(c) = chars.next() {
        column += 1;
        match c {
            '\n' => {
                finish_word(&mut current, &mut words);
                if !words.is_empty() {
                    let line0 = words[0].line;
                    commands.push(CommandLine {
                        words: std::mem::take(&mut words),
                        line: line0,
                    });
                }
                line += 1;
                column = 0;
            }
            ' ' | '\t' | '\r' => finish_word(&mut current, &mut words),
            '#' if current.is_none() => {
                // A comment runs to the end of the line.
                while chars.peek().is_some_and(|&n| n != '\n') {
                    chars.next();
                }
            }
            '\\' => match chars.next() {
                Some('\n') => {
                    // A continuation: the command goes on on the next line.
                    finish_word(&mut current, &mut words);
                    line += 1;
                    column = 0;
                }
                Some(n) => {
                    start(&mut current, line, column);
                    column += 1;
                    if let Some(w) = current.as_mut() {
                        w.text.push(n);
                    }
                }
                None => {}
            },
            '\'' | '"' => {
                let (qline, qcol) = (line, column);
                let fresh = current.is_none();
                start(&mut current, line, column);
                if let Some(w) = current.as_mut().filter(|_| fresh) {
                    w.quote = 1;
                }
                let mut closed = false;
                while let Some(n) = chars.next() {
                    column += 1;
                    if n == c {
                        closed = true;
                        break;
                    }
                    if n == '\n' {
                        line += 1;
                        column = 0;
                    }
                    let n = match (c, n) {
                        // Inside "…" a backslash escapes only these, as in sh.
                        ('"', '\\') if matches!(chars.peek(), Some('"' | '\\' | '$' | '`')) => {
                            column += 1;
                            chars.next().unwrap_or('\\')
                        }
                        _ => n,
                    };
                    if let Some(w) = current.as_mut() {
                        w.text.push(n);
                    }
                }
                if !closed {
                    return Err(located(
                        qline,
                        qcol,
                        format!("this {c} is never closed: close it on the same command"),
                    ));
                }
            }
            _ => {
                start(&mut current, line, column);
                if let Some(w) = current.as_mut() {
                    w.text.push(c);
                }
            }
        }
    }
    finish_word(&mut current, &mut words);
    if !words.is_empty() {
        let line0 = words[0].line;
        commands.push(CommandLine { words, line: line0 });
    }
    Ok(commands)
}

/// The flags of one command: each with whether it takes a value and whether that value is a
/// comma list (clap's `value_delimiter = ','`), and repeated (`Vec`).
struct Flag {
    name: &'static str,
    takes_value: bool,
    comma_list: bool,
    repeats: bool,
}

const fn flag(name: &'static str, takes_value: bool, comma_list: bool, repeats: bool) -> Flag {
    Flag {
        name,
        takes_value,
        comma_list,
        repeats,
    }
}

const KIN_FLAGS: &[Flag] = &[
    flag("--polar", true, false, false),
    flag("--path", true, false, false),
    flag("--param", true, false, false),
    flag("--speed", true, false, false),
    flag("--at", true, false, true),
    flag("--set", true, true, true),
    flag("--max", true, false, false),
    flag("--over", true, false, false),
    flag("--signed", true, true, true),
    flag("--format", true, false, false),
    flag("--json", false, false, false),
];

const DSOLVE_FLAGS: &[Flag] = &[
    flag("--ic", true, false, false),
    flag("--rule", true, false, false),
    flag("--set", true, true, true),
    flag("--at", true, true, true),
    flag("--when", true, false, false),
    flag("--signed", true, true, true),
    flag("--format", true, false, false),
    flag("--json", false, false, false),
];

/// A command's words read against its flags: the values of each flag given, the positional
/// words, and the word each came from (to locate errors).
struct Parsed<'w> {
    values: Vec<(&'static str, String, &'w Word)>,
    positional: Vec<&'w Word>,
}

impl Parsed<'_> {
    fn one(&self, name: &str) -> Option<String> {
        self.values
            .iter()
            .find(|(n, ..)| *n == name)
            .map(|(_, v, _)| v.clone())
    }

    fn all(&self, name: &str) -> Vec<String> {
        self.values
            .iter()
            .filter(|(n, ..)| *n == name)
            .map(|(_, v, _)| v.clone())
            .collect()
    }

    fn given(&self, name: &str) -> bool {
        self.values.iter().any(|(n, ..)| *n == name)
    }

    fn notation(&self) -> Result<Notation, Error> {
        match self.one("--format").as_deref() {
            None | Some("text") => Ok(Notation::Text),
            Some("latex") => Ok(Notation::Latex),
            Some("rust") => Ok(Notation::Rust),
            Some(other) => Err(Error::argument(
                "--format",
                format!("`{other}` is not a notation; valid: text, latex, rust"),
            )),
        }
    }
}

/// Reads `words` (after `pdyn COMMAND`) as the CLI would.
fn parse<'w>(
    command: &str,
    words: &'w [Word],
    flags: &[Flag],
) -> Result<Parsed<'w>, (Box<Error>, &'w Word)> {
    let mut parsed = Parsed {
        values: Vec::new(),
        positional: Vec::new(),
    };
    let mut rest = words.iter();
    let mut only_positional = false;
    while let Some(w) = rest.next() {
        if only_positional || !w.text.starts_with("--") {
            parsed.positional.push(w);
            continue;
        }
        if w.text == "--" {
            only_positional = true;
            continue;
        }
        let (name, inline) = match w.text.split_once('=') {
            Some((n, v)) => (n, Some(v.to_string())),
            None => (w.text.as_str(), None),
        };
        let Some(f) = flags.iter().find(|f| f.name == name) else {
            let valid: Vec<&str> = flags.iter().map(|f| f.name).collect();
            let why = if name == "--data" || name == "--columns" || name == "--from" {
                format!("{name} reads a file: measured data runs from the command line (`pdyn {command} --data FILE`), not in the page")
            } else {
                format!(
                    "`{name}` is not an option of `pdyn {command}`; valid: {}",
                    valid.join(", ")
                )
            };
            return Err((Box::new(Error::argument(name, why)), w));
        };
        if !f.repeats && parsed.given(f.name) {
            let why = format!("{} is given twice: give it once", f.name);
            return Err((Box::new(Error::argument(f.name, why)), w));
        }
        if !f.takes_value {
            if inline.is_some() {
                return Err((
                    Box::new(Error::argument(
                        f.name,
                        format!("{} takes no value", f.name),
                    )),
                    w,
                ));
            }
            parsed.values.push((f.name, String::new(), w));
            continue;
        }
        let (value, from) = match inline {
            Some(v) => (v, w),
            None => match rest.next() {
                Some(v) => (v.text.clone(), v),
                None => {
                    return Err((
                        Box::new(Error::argument(f.name, format!("{} needs a value", f.name))),
                        w,
                    ))
                }
            },
        };
        if f.comma_list {
            for part in value.split(',') {
                parsed.values.push((f.name, part.to_string(), from));
            }
        } else {
            parsed.values.push((f.name, value, from));
        }
    }
    Ok(parsed)
}

/// `pdyn kin …`'s input from its words.
fn kin_input(p: &Parsed) -> Result<KinInput, Error> {
    if p.positional.len() > 1 {
        return Err(Error::argument(
            "<position>",
            format!(
                "one position is read, {} words were given: quote a position that has spaces",
                p.positional.len()
            ),
        ));
    }
    let defaults = KinInput::new();
    Ok(KinInput {
        position: p.positional.first().map(|w| w.text.clone()),
        polar: p.one("--polar"),
        path: p.one("--path"),
        param: p.one("--param").unwrap_or(defaults.param),
        speed: p.one("--speed").unwrap_or(defaults.speed),
        at: p.all("--at"),
        set: p.all("--set"),
        max: p.one("--max"),
        over: p.one("--over"),
        signed: p.all("--signed"),
    })
}

/// `pdyn dsolve …`'s input from its words.
fn dsolve_input(p: &Parsed) -> DsolveInput {
    DsolveInput {
        equations: p.positional.iter().map(|w| w.text.clone()).collect(),
        ic: p.one("--ic"),
        rule: p.one("--rule"),
        set: p.all("--set"),
        at: p.all("--at"),
        when: p.one("--when"),
        signed: p.all("--signed"),
    }
}

/// Where in the script an error of a command belongs: the word of the expression that failed
/// (and the column inside it), the option named, or else `fallback` (the command's first
/// word; `words`, its arguments, may be empty).
fn place(
    error: &Error,
    parsed: Option<&Parsed>,
    words: &[Word],
    fallback: (usize, usize),
) -> (usize, usize) {
    let at_word = |w: &Word, offset: usize| (w.line, w.column + w.quote + offset);
    if let Error::Expr { text, error: e, .. } = error {
        let hit = words.iter().find(|w| w.text == *text).or_else(|| {
            // A comma list's item: the word that holds it.
            words.iter().find(|w| w.text.contains(text.as_str()))
        });
        if let Some(w) = hit {
            let chars = |s: &str, end: usize| s.get(..end).map_or(0, |p| p.chars().count());
            let before = w.text.find(text.as_str()).unwrap_or(0);
            let offset = chars(&w.text, before) + chars(text, e.span.start);
            return at_word(w, offset);
        }
    }
    if let Error::Argument { argument, .. } = error {
        let given = parsed.and_then(|p| p.values.iter().find(|(n, ..)| *n == argument.as_str()));
        if let Some((_, _, w)) = given {
            return at_word(w, 0);
        }
        if let Some(w) = words.iter().find(|w| w.text == *argument) {
            return at_word(w, 0);
        }
    }
    fallback
}

/// One command's output: its text and JSON, as `pdyn kin`/`pdyn dsolve` print them.
fn run_command(line: &CommandLine) -> Result<Value, Located> {
    let words = &line.words;
    let fail = |error: Box<Error>, (line, column): (usize, usize)| Located {
        error,
        line,
        column,
    };
    if words[0].text != "pdyn" {
        return Err(fail(
            Box::new(Error::argument(
                "script",
                format!(
                    "`{}`: the page runs `pdyn kin …` and `pdyn dsolve …` lines (and `#` comments)",
                    words[0].text
                ),
            )),
            (words[0].line, words[0].column),
        ));
    }
    let Some(command) = words.get(1) else {
        return Err(fail(
            Box::new(Error::argument(
                "script",
                "`pdyn` alone: write `pdyn kin …` or `pdyn dsolve …`",
            )),
            (words[0].line, words[0].column),
        ));
    };
    let flags = match command.text.as_str() {
        "kin" => KIN_FLAGS,
        "dsolve" => DSOLVE_FLAGS,
        other => {
            return Err(fail(
                Box::new(Error::argument(
                    "script",
                    format!("`pdyn {other}` runs on a model: open the model file and use the buttons; script lines run `pdyn kin` and `pdyn dsolve`"),
                )),
                (command.line, command.column),
            ))
        }
    };
    let args = &words[2..];
    let parsed =
        parse(&command.text, args, flags).map_err(|(error, w)| fail(error, (w.line, w.column)))?;
    let result = (|| {
        let notation = parsed.notation()?;
        let (text, json_text) = if command.text == "kin" {
            let r = pdyn::kin::kin(&kin_input(&parsed)?)?;
            (
                pdyn::report::kin::report(&r, notation, false),
                pdyn::report::kin::report(&r, notation, true),
            )
        } else {
            let r = pdyn::dsolve::dsolve(&dsolve_input(&parsed))?;
            (
                pdyn::report::dsolve::report(&r, notation, false),
                pdyn::report::dsolve::report(&r, notation, true),
            )
        };
        let result: Value = serde_json::from_str(&json_text).map_err(|e| Error::Internal {
            message: format!(
                "pdyn {} printed JSON that does not parse: {e}",
                command.text
            ),
        })?;
        Ok(json!({
            "line": line.line,
            "command": words.iter().map(|w| w.text.as_str()).collect::<Vec<_>>(),
            "name": command.text,
            "text": text,
            "result": result,
        }))
    })();
    result.map_err(|error: Error| {
        let at = place(
            &error,
            Some(&parsed),
            args,
            (words[0].line, words[0].column),
        );
        fail(Box::new(error), at)
    })
}

/// Runs every command line of `script` in order; the first error stops it, located. A line
/// ending in `|| true` may fail, as in `sh`: its error is its output (`"failed": true`, the
/// CLI's `{"error": …}` JSON as `result`) and the script goes on.
pub fn run(script: &str) -> Result<Vec<Value>, Located> {
    let mut lines = split(script)?;
    if lines.is_empty() {
        return Err(located(
            1,
            1,
            "the script has no command: write lines such as `pdyn kin --polar \"r = t, theta = t^2\"`".into(),
        ));
    }
    let mut out = Vec::with_capacity(lines.len());
    for line in &mut lines {
        let n = line.words.len();
        let may_fail = n > 2 && line.words[n - 2].text == "||" && line.words[n - 1].text == "true";
        if may_fail {
            line.words.truncate(n - 2);
        }
        match run_command(line) {
            Ok(v) => out.push(v),
            Err(e) if may_fail => out.push(json!({
                "line": line.line,
                "command": line.words.iter().map(|w| w.text.as_str()).collect::<Vec<_>>(),
                "name": line.words.get(1).map_or("", |w| w.text.as_str()),
                "text": e.error.to_string(),
                "result": e.error.to_json(),
                "failed": true,
            })),
            Err(e) => return Err(e),
        }
    }
    Ok(out)
}

/// Whether `text` is a script of command lines rather than a model file: its first line that
/// is not blank or a comment starts with `pdyn`.
pub fn is_script(text: &str) -> bool {
    text.lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
        .is_some_and(|l| l == "pdyn" || l.starts_with("pdyn "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texts(c: &CommandLine) -> Vec<&str> {
        c.words.iter().map(|w| w.text.as_str()).collect()
    }

    #[test]
    fn words_split_as_sh_splits_them() {
        let s = "#!/usr/bin/env sh\n# a comment\npdyn kin --polar \"r = t, theta = t^2\" --at theta=pi\n\npdyn dsolve 'x'\"''\"' = 0' \\\n  --ic \"x(0)=1, x'(0)=0\"  # trailing\n";
        let c = split(s).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(
            texts(&c[0]),
            [
                "pdyn",
                "kin",
                "--polar",
                "r = t, theta = t^2",
                "--at",
                "theta=pi"
            ]
        );
        assert_eq!(c[0].line, 3);
        // The quoted word starts at its quote (column 18), its text one column later.
        assert_eq!((c[0].words[3].column, c[0].words[3].quote), (18, 1));
        assert_eq!(
            texts(&c[1]),
            ["pdyn", "dsolve", "x'' = 0", "--ic", "x(0)=1, x'(0)=0"]
        );
        assert_eq!((c[1].words[3].line, c[1].words[3].column), (6, 3));
    }

    #[test]
    fn an_unclosed_quote_is_located_at_the_quote() {
        let e = split("pdyn kin \"[t, 0, 0]\npdyn kin x").unwrap_err();
        assert_eq!((e.line, e.column), (1, 10));
        assert!(e.error.to_string().contains("never closed"));
    }

    #[test]
    fn flags_and_comma_lists_read_as_the_cli_reads_them() {
        let c = split("pdyn kin --path \"y = A*sin(x)\" --set A=2,L=50 --at x=1 --at=x=2 --json")
            .unwrap();
        let p = parse("kin", &c[0].words[2..], KIN_FLAGS).unwrap();
        let k = kin_input(&p).unwrap();
        assert_eq!(k.path.as_deref(), Some("y = A*sin(x)"));
        assert_eq!(k.set, ["A=2", "L=50"]);
        assert_eq!(k.at, ["x=1", "x=2"]);
        assert_eq!((k.param.as_str(), k.speed.as_str()), ("s", "V"));
        // As in sh, `''` unquoted is an empty word part; after `--` every word is an equation.
        let c = split("pdyn dsolve \"x''=-x\" --at 0,1.5 -- \"-y''=y\"").unwrap();
        let p = parse("dsolve", &c[0].words[2..], DSOLVE_FLAGS).unwrap();
        let d = dsolve_input(&p);
        assert_eq!(d.equations, ["x''=-x", "-y''=y"]);
        assert_eq!(d.at, ["0", "1.5"]);
    }

    #[test]
    fn errors_point_at_the_word_that_caused_them() {
        // An unknown option: at the option.
        let e = run("pdyn kin \"[t, 0, 0]\" --speeed 3").unwrap_err();
        assert_eq!((e.line, e.column), (1, 22));
        assert!(e.error.to_string().contains("--speed"), "{}", e.error);
        // A file option: said to belong to the command line.
        let e = run("pdyn kin --data track.csv").unwrap_err();
        assert!(
            e.error.to_string().contains("not in the page"),
            "{}",
            e.error
        );
        // An expression that does not parse: inside the quoted word, at the bad character.
        let e = run("# c\npdyn kin \"[t, t^, 0]\"").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.column > 10 && e.column <= 20, "column {}", e.column);
        // A line that is not pdyn kin/dsolve.
        let e = run("pdyn run examples/satellite.toml").unwrap_err();
        assert_eq!((e.line, e.column), (1, 6));
        let e = run("ls -l").unwrap_err();
        assert_eq!((e.line, e.column), (1, 1));
        assert!(run("# only a comment\n").is_err());
        // A command with no arguments: the library's error, at the command (was a panic).
        for bare in ["pdyn kin", "pdyn dsolve", "  pdyn kin --at"] {
            let e = run(bare).unwrap_err();
            assert_eq!(e.line, 1, "{bare}");
        }
        // A word with characters of several bytes before the error.
        let e = run("pdyn kin \"[θ*t, t^, 0]\"").unwrap_err();
        assert!(e.column > 10, "column {}", e.column);
    }

    #[test]
    fn commands_print_what_the_cli_prints() {
        // Circular motion at constant rate: a = -R omega^2 (cos, sin, 0), computed here
        // independently of the report.
        let out =
            run("pdyn kin \"[R*cos(omega*t), R*sin(omega*t), 0]\" --at t=0 --set R=2,omega=3")
                .unwrap();
        assert_eq!(out.len(), 1);
        let a = &out[0]["result"]["at"][0]["values"]["a"]["value"];
        assert_eq!(a[0].as_f64(), Some(-2.0 * 9.0));
        assert!(out[0]["text"].as_str().unwrap().contains("a = "));
        let out = run("pdyn dsolve \"x'' = -4*x\" --ic \"x(0)=1, x'(0)=0\" --at 0.5").unwrap();
        let x = out[0]["result"]["cases"][0]["at"][0]["values"][0]
            .as_f64()
            .unwrap();
        assert!((x - libm::cos(1.0f64)).abs() < 1e-14, "{x}");
    }

    #[test]
    fn a_line_that_may_fail_shows_its_error_and_the_script_goes_on() {
        let out = run("pdyn dsolve \"x'' + sin(x) = 0\" --ic \"x(0)=1, x'(0)=0\" || true\npdyn kin \"[t, 0, 0]\"").unwrap();
        assert_eq!(out.len(), 2);
        assert_eq!(out[0]["failed"], true);
        assert_eq!(out[0]["result"]["error"]["exit_code"], 2);
        assert_eq!(
            out[0]["command"].as_array().unwrap().len(),
            5,
            "`|| true` is not a word of the command"
        );
        assert!(out[1]["result"]["quantities"].is_object());
        // Without `|| true` the same line stops the script.
        assert!(run(
            "pdyn dsolve \"x'' + sin(x) = 0\" --ic \"x(0)=1, x'(0)=0\"\npdyn kin \"[t, 0, 0]\""
        )
        .is_err());
    }

    #[test]
    fn scripts_are_told_from_models() {
        assert!(is_script("#!/usr/bin/env sh\n# x\npdyn kin \"[t,0,0]\""));
        assert!(!is_script("name = \"m\"\n[parameters]\n"));
        assert!(!is_script("# pdyn kin in a comment\nname = \"x\""));
    }
}
