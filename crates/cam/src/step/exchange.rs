//! The exchange structure (ISO 10303-21 §7–10): HEADER and DATA sections parsed into entity
//! instances — simple (`#1 = NAME(…)`) or complex (`#2 = (A(…) B(…))`) — indexed by `#id`,
//! schema-free. `entity` then gives typed views of them with errors that name the instance.

use std::collections::HashMap;

use super::error::StepError;
use super::lexer::{tokenize, Lexed, Token};

/// Lists deeper than this are refused: STEP needs three levels (a weight grid inside a
/// record), and a bound keeps the recursive parser's stack small on hostile input.
pub(crate) const MAX_NESTING: usize = 32;

/// One attribute value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Param {
    Ref(u64),
    Integer(i64),
    Real(f64),
    String(String),
    Enum(String),
    Binary(String),
    List(Vec<Param>),
    /// A typed value, `LENGTH_MEASURE(25.4)`.
    Typed(String, Box<Param>),
    Unset,
    Derived,
}

/// `NAME(attributes)`: a simple instance, or one partial type of a complex instance.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Record {
    pub name: String,
    pub params: Vec<Param>,
}

/// An entity instance: one record when simple, the partial records of a complex instance in
/// the file's (alphabetical, by Part 21) order otherwise.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Instance {
    pub line: usize,
    pub complex: bool,
    pub records: Vec<Record>,
}

impl Instance {
    /// The type as shown in errors: the record name, or the partial names joined by `+`.
    pub fn type_name(&self) -> String {
        let names: Vec<&str> = self.records.iter().map(|r| r.name.as_str()).collect();
        names.join("+")
    }

    pub fn record(&self, name: &str) -> Option<&Record> {
        self.records.iter().find(|r| r.name == name)
    }

    pub fn has(&self, name: &str) -> bool {
        self.record(name).is_some()
    }
}

/// The DATA section(s) of a file, by instance name, and the header's schema names.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Exchange {
    pub schemas: Vec<String>,
    pub instances: HashMap<u64, Instance>,
}

impl Exchange {
    /// Instance names in increasing order (a stable order for walks over the whole file).
    pub fn ids(&self) -> Vec<u64> {
        let mut ids: Vec<u64> = self.instances.keys().copied().collect();
        ids.sort_unstable();
        ids
    }
}

/// Parses a whole exchange structure: `ISO-10303-21; HEADER; … ENDSEC; DATA; … ENDSEC;
/// END-ISO-10303-21;` (several DATA sections are merged; ANCHOR, REFERENCE and SIGNATURE
/// sections are skipped).
pub(crate) fn parse(text: &[u8]) -> Result<Exchange, StepError> {
    let tokens = tokenize(text)?;
    let mut p = Parser { t: &tokens, i: 0 };
    p.keyword("ISO-10303-21")?;
    p.expect(&Token::Semicolon, "`;`")?;
    p.keyword("HEADER")?;
    p.expect(&Token::Semicolon, "`;`")?;
    let mut ex = Exchange::default();
    // Header entities: FILE_DESCRIPTION, FILE_NAME, FILE_SCHEMA and user ones.
    while !p.at_keyword("ENDSEC") {
        let record = p.record(0)?;
        p.expect(&Token::Semicolon, "`;`")?;
        if record.name == "FILE_SCHEMA" {
            if let Some(Param::List(names)) = record.params.first() {
                ex.schemas = names
                    .iter()
                    .filter_map(|n| match n {
                        Param::String(s) => Some(s.clone()),
                        _ => None,
                    })
                    .collect();
            }
        }
    }
    p.keyword("ENDSEC")?;
    p.expect(&Token::Semicolon, "`;`")?;
    loop {
        let line = p.line();
        match p.next_keyword()?.as_str() {
            "END-ISO-10303-21" => {
                p.expect(&Token::Semicolon, "`;`")?;
                break;
            }
            "DATA" => {
                if p.peek() == Some(&Token::Open) {
                    p.params(0)?; // DATA('name', (schema)): parameters of the section
                }
                p.expect(&Token::Semicolon, "`;`")?;
                p.data(&mut ex)?;
            }
            "ANCHOR" | "REFERENCE" | "SIGNATURE" => p.skip_section()?,
            other => {
                return Err(StepError::Syntax {
                    line,
                    message: format!("expected DATA or END-ISO-10303-21, found `{other}`"),
                })
            }
        }
    }
    Ok(ex)
}

struct Parser<'a> {
    t: &'a [Lexed],
    i: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Token> {
        self.t.get(self.i).map(|l| &l.token)
    }

    /// The line of the next token (or of the last one at the end of the file).
    fn line(&self) -> usize {
        self.t.get(self.i).or(self.t.last()).map_or(1, |l| l.line)
    }

    fn error(&self, expected: &str) -> StepError {
        let found = match self.peek() {
            None => "the end of the file".to_string(),
            Some(t) => describe(t),
        };
        StepError::Syntax {
            line: self.line(),
            message: format!("expected {expected}, found {found}"),
        }
    }

    fn expect(&mut self, t: &Token, what: &str) -> Result<(), StepError> {
        if self.peek() == Some(t) {
            self.i += 1;
            Ok(())
        } else {
            Err(self.error(what))
        }
    }

    fn at_keyword(&self, k: &str) -> bool {
        matches!(self.peek(), Some(Token::Keyword(w)) if w == k)
    }

    fn keyword(&mut self, k: &str) -> Result<(), StepError> {
        if self.at_keyword(k) {
            self.i += 1;
            Ok(())
        } else {
            Err(self.error(&format!("`{k}`")))
        }
    }

    fn next_keyword(&mut self) -> Result<String, StepError> {
        match self.peek() {
            Some(Token::Keyword(w)) => {
                let w = w.clone();
                self.i += 1;
                Ok(w)
            }
            _ => Err(self.error("a keyword")),
        }
    }

    fn skip_section(&mut self) -> Result<(), StepError> {
        while !self.at_keyword("ENDSEC") {
            if self.peek().is_none() {
                return Err(self.error("`ENDSEC`"));
            }
            self.i += 1;
        }
        self.i += 1;
        self.expect(&Token::Semicolon, "`;`")
    }

    /// Entity instances up to `ENDSEC;`.
    fn data(&mut self, ex: &mut Exchange) -> Result<(), StepError> {
        loop {
            let line = self.line();
            match self.peek() {
                Some(Token::Keyword(k)) if k == "ENDSEC" => {
                    self.i += 1;
                    return self.expect(&Token::Semicolon, "`;`");
                }
                Some(Token::Ref(id)) => {
                    let id = *id;
                    self.i += 1;
                    self.expect(&Token::Equals, "`=`")?;
                    let (complex, records) = if self.peek() == Some(&Token::Open) {
                        self.i += 1;
                        let mut records = Vec::new();
                        while self.peek() != Some(&Token::Close) {
                            records.push(self.record(0)?);
                        }
                        self.i += 1;
                        if records.is_empty() {
                            return Err(StepError::Syntax {
                                line,
                                message: format!("complex instance #{id} has no records"),
                            });
                        }
                        (true, records)
                    } else {
                        (false, vec![self.record(0)?])
                    };
                    self.expect(&Token::Semicolon, "`;`")?;
                    let instance = Instance {
                        line,
                        complex,
                        records,
                    };
                    if let Some(first) = ex.instances.get(&id) {
                        return Err(StepError::Duplicate {
                            id,
                            line,
                            first: first.line,
                        });
                    }
                    ex.instances.insert(id, instance);
                }
                _ => return Err(self.error("an entity instance `#id = …;` or `ENDSEC`")),
            }
        }
    }

    /// `KEYWORD(params)`.
    fn record(&mut self, depth: usize) -> Result<Record, StepError> {
        let name = self.next_keyword()?;
        let params = self.params(depth)?;
        Ok(Record { name, params })
    }

    /// `( [param {, param}] )`.
    fn params(&mut self, depth: usize) -> Result<Vec<Param>, StepError> {
        if depth > MAX_NESTING {
            return Err(StepError::Syntax {
                line: self.line(),
                message: format!("lists nested deeper than {MAX_NESTING}"),
            });
        }
        self.expect(&Token::Open, "`(`")?;
        let mut out = Vec::new();
        if self.peek() == Some(&Token::Close) {
            self.i += 1;
            return Ok(out);
        }
        loop {
            out.push(self.param(depth)?);
            match self.peek() {
                Some(Token::Comma) => self.i += 1,
                Some(Token::Close) => {
                    self.i += 1;
                    return Ok(out);
                }
                _ => return Err(self.error("`,` or `)`")),
            }
        }
    }

    fn param(&mut self, depth: usize) -> Result<Param, StepError> {
        let Some(t) = self.peek() else {
            return Err(self.error("a parameter"));
        };
        let p = match t {
            Token::Open => return self.params(depth + 1).map(Param::List),
            Token::Keyword(k) => {
                let k = k.clone();
                self.i += 1;
                let mut inner = self.params(depth + 1)?;
                if inner.len() != 1 {
                    return Err(StepError::Syntax {
                        line: self.line(),
                        message: format!("typed parameter {k}(…) must hold one value"),
                    });
                }
                return Ok(Param::Typed(k, Box::new(inner.remove(0))));
            }
            Token::Ref(id) => Param::Ref(*id),
            Token::Integer(v) => Param::Integer(*v),
            Token::Real(v) => Param::Real(*v),
            Token::String(s) => Param::String(s.clone()),
            Token::Enum(s) => Param::Enum(s.clone()),
            Token::Binary(s) => Param::Binary(s.clone()),
            Token::Unset => Param::Unset,
            Token::Derived => Param::Derived,
            _ => return Err(self.error("a parameter")),
        };
        self.i += 1;
        Ok(p)
    }
}

fn describe(t: &Token) -> String {
    match t {
        Token::Keyword(k) => format!("`{k}`"),
        Token::Ref(id) => format!("`#{id}`"),
        Token::Integer(v) => format!("`{v}`"),
        Token::Real(v) => format!("`{v}`"),
        Token::String(_) => "a string".to_string(),
        Token::Enum(e) => format!("`.{e}.`"),
        Token::Binary(_) => "a binary".to_string(),
        Token::Unset => "`$`".to_string(),
        Token::Derived => "`*`".to_string(),
        Token::Open => "`(`".to_string(),
        Token::Close => "`)`".to_string(),
        Token::Comma => "`,`".to_string(),
        Token::Semicolon => "`;`".to_string(),
        Token::Equals => "`=`".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n";

    fn file(data: &str) -> String {
        format!("{HEAD}{data}\nENDSEC;\nEND-ISO-10303-21;\n")
    }

    #[test]
    fn parses_simple_and_complex_instances() {
        let ex = parse(
            file(
                "#1 = A('n', (#2, #3), 1.5, .T., $, *);\n#2 = ( B() C(LENGTH_MEASURE(25.4), #1) );",
            )
            .as_bytes(),
        )
        .unwrap();
        assert_eq!(ex.schemas, vec!["AUTOMOTIVE_DESIGN".to_string()]);
        let a = &ex.instances[&1];
        assert_eq!(a.line, 7);
        assert!(!a.complex);
        assert_eq!(
            a.records[0].params,
            vec![
                Param::String("n".into()),
                Param::List(vec![Param::Ref(2), Param::Ref(3)]),
                Param::Real(1.5),
                Param::Enum("T".into()),
                Param::Unset,
                Param::Derived,
            ]
        );
        let b = &ex.instances[&2];
        assert!(b.complex);
        assert_eq!(b.type_name(), "B+C");
        assert_eq!(
            b.record("C").unwrap().params[0],
            Param::Typed("LENGTH_MEASURE".into(), Box::new(Param::Real(25.4)))
        );
    }

    #[test]
    fn syntax_errors_name_the_line() {
        let e = parse(file("#1 = A(1,2;").as_bytes()).unwrap_err();
        assert_eq!(e.to_string(), "line 7: expected `,` or `)`, found `;`");
        let e = parse(file("#1 = A(1);\n#1 = B(2);").as_bytes()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 8: #1 is defined again (first on line 7)"
        );
        let e = parse(file(".....").as_bytes()).unwrap_err();
        assert_eq!(e.to_string(), "line 7: a number needs digits");
        let e = parse(b"ISO-10303-21;\nHEADER;").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 2: expected a keyword, found the end of the file"
        );
    }

    #[test]
    fn deep_nesting_is_refused() {
        let deep = format!("#1 = A({}1{});", "(".repeat(100), ")".repeat(100));
        let e = parse(file(&deep).as_bytes()).unwrap_err();
        assert_eq!(e.to_string(), "line 7: lists nested deeper than 32");
    }
}
