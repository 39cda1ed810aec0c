//! The flags' own value parsers: a value no run can use is a usage error, refused before
//! anything runs.

/// `--threads`: 0 would leave no worker, whatever the command does first (a cache hit too).
pub(crate) fn parse_threads(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(e.to_string()),
    }
}

/// A number that must be finite (`--exposure`): NaN or infinity would make every pixel NaN.
pub(crate) fn parse_finite(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(x) => Err(format!("{x} is not a finite number")),
        Err(e) => Err(e.to_string()),
    }
}

pub(crate) fn parse_rect(s: &str) -> Result<[usize; 4], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>().map_err(|e| format!("`{t}`: {e}")))
        .collect::<Result<_, _>>()?;
    <[usize; 4]>::try_from(v).map_err(|_| "expected x0,y0,x1,y1".to_string())
}

/// `-D NAME=VALUE`: a parameter name (letters, digits, `_`) and its value.
pub(crate) fn parse_define(s: &str) -> Result<(String, String), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected NAME=VALUE"))?;
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "`{name}`: a parameter name is letters, digits and `_`"
        ));
    }
    Ok((name.to_string(), value.to_string()))
}
