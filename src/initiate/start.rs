//! Where the birds start (§6: "birds sitting on the ground" or scattered in the air): the start's
//! kinds ([`Start`]), a start read from a file ([`StartState`]), the random draws of each kind, and
//! the simulation set up from them ([`start_simulation`]).

use super::*;

/// Draws of a start heading and speed per bird before the one with the largest predicted miss
/// distance is kept ([`random_start`]).
pub const START_DRAWS: usize = 100;

/// Largest accepted width or depth of the random start region, wingspans.
pub const MAX_START_EXTENT: f64 = 1e6;

/// Width over depth of the automatic take-off area (before [`GROUND_MAX_DEPTH`] makes it wider).
pub const GROUND_ASPECT: f64 = 3.0;

/// Largest depth of the automatic take-off area, wingspans: a deeper one leaves the birds at its
/// back (whose slots are near the apex of the V) more than 30 wingspans from every slot when the
/// last of them lifts off.
pub const GROUND_MAX_DEPTH: f64 = 22.0;

/// Smallest automatic width of the paper's airborne start region, wingspans.
pub const AIR_MIN_WIDTH: f64 = 20.0;

/// Automatic width of the airborne start region per square root of the flock's bird count,
/// wingspans (used when it exceeds [`AIR_MIN_WIDTH`]).
pub const AIR_WIDTH_PER_ROOT_BIRD: f64 = 4.5;

/// Automatic depth of the airborne start region: half its width, within these bounds,
/// wingspans. Shallow and wide like the V the birds fly into: a deeper region leaves the birds
/// at its back far from every slot (in a 30 × 30 region they began 24 wingspans from the
/// nearest one).
pub const AIR_DEPTH_RANGE: (f64, f64) = (10.0, 15.0);

/// Half-height of the band the airborne start scatters the birds in around the cruise altitude,
/// wingspans.
pub const AIR_HEIGHT_BAND: f64 = 1.5;

/// The airborne start's headings: no two birds predicted (flying straight) to come closer than
/// this within [`START_HORIZON`], wingspans (redrawn up to [`START_DRAWS`] times).
pub const START_MISS: f64 = 1.0;

/// The airborne start's heading draws look this far ahead, seconds.
pub const START_HORIZON: f64 = 1.5;

/// Where the birds start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Start {
    /// At rest on the ground (or water) in a take-off area, leaving in a staggered order.
    Ground(GroundStart),
    /// The paper's start: scattered in the air, random positions, headings and speeds in a
    /// region, at the cruise altitude.
    Random(StartRegion),
    /// Given positions (and optionally headings and speeds), in the air at the cruise altitude.
    Given(StartState),
}

/// A take-off from the ground: birds at rest in a rectangle centred on the origin (its width
/// across and its depth along the cruise heading), at least `min_spacing` apart, facing within
/// `heading_spread` of the cruise heading; they leave front to back over the stagger window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroundStart {
    /// Width across the cruise heading, wingspans (`None`: from the take-off plan).
    pub width: Option<f64>,
    /// Depth along the cruise heading, wingspans (`None`: from the take-off plan).
    pub depth: Option<f64>,
    /// Half-width of the heading distribution around the cruise heading, radians.
    pub heading_spread: f64,
    /// Minimum distance between two birds on the ground, wingspans.
    pub min_spacing: f64,
    /// Time between the first and the last departure, seconds (`None`: from the take-off plan).
    pub stagger: Option<f64>,
}

impl Default for GroundStart {
    fn default() -> Self {
        GroundStart {
            width: None,
            depth: None,
            heading_spread: 5f64.to_radians(),
            min_spacing: 2.0,
            stagger: None,
        }
    }
}

/// A random take-off: positions uniform in a rectangle centred on the origin, its width across
/// and its depth along the cruise heading, at least `min_spacing` apart; headings uniform within
/// `heading_spread` of the cruise heading; speeds uniform between the minimum and the cruise speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StartRegion {
    /// Width across the cruise heading, wingspans (`None`: 20, or 4.5√N for more than 19 birds).
    pub width: Option<f64>,
    /// Depth along the cruise heading, wingspans (`None`: half the width, 10 to 15).
    pub depth: Option<f64>,
    /// Half-width of the heading distribution around the cruise heading, radians (π: any heading).
    pub heading_spread: f64,
    /// Minimum distance between two birds at the start, wingspans.
    pub min_spacing: f64,
}

impl Default for StartRegion {
    fn default() -> Self {
        StartRegion {
            width: None,
            depth: None,
            heading_spread: PI,
            min_spacing: 1.5,
        }
    }
}

/// A start chosen by name, as a command line or a config file gives it: the kind (`ground`,
/// `air` for the paper's scattered start, or else the path of a start file) and optional
/// overrides of the start's region. Angles are in degrees, as people give them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StartChoice {
    /// `ground`, `air`, or the path of a start file.
    pub kind: String,
    /// Width of the take-off area or start region across the cruise heading, wingspans.
    pub width: Option<f64>,
    /// Depth of the take-off area or start region along the cruise heading, wingspans.
    pub depth: Option<f64>,
    /// Half-width of the start headings around the cruise heading, degrees.
    pub heading_spread_deg: Option<f64>,
}

impl Start {
    /// The word that names this kind of start: `ground`, `air` or `file`.
    pub fn word(&self) -> &'static str {
        match self {
            Start::Ground(_) => "ground",
            Start::Random(_) => "air",
            Start::Given(_) => "file",
        }
    }

    /// The start `choice` names for a flock of `birds`: a start file is read (and checked
    /// against the flock); the region overrides apply to `ground` and `air` only, and giving one
    /// with a start file is an error naming it (`initiate.start.width`, `.depth`,
    /// `.heading_spread`). A heading spread equal to the default's display in degrees is the
    /// default exactly.
    pub fn from_choice(choice: &StartChoice, birds: usize) -> Result<Start> {
        let spread = |default: f64| {
            choice.heading_spread_deg.map_or(default, |h| {
                if h == display_degrees(default) {
                    default
                } else {
                    h.to_radians()
                }
            })
        };
        Ok(match choice.kind.as_str() {
            "ground" => {
                let g = GroundStart::default();
                Start::Ground(GroundStart {
                    width: choice.width,
                    depth: choice.depth,
                    heading_spread: spread(g.heading_spread),
                    ..g
                })
            }
            "air" => {
                let r = StartRegion::default();
                Start::Random(StartRegion {
                    width: choice.width,
                    depth: choice.depth,
                    heading_spread: spread(r.heading_spread),
                    ..r
                })
            }
            path => {
                for (name, given) in [
                    ("initiate.start.width", choice.width.is_some()),
                    ("initiate.start.depth", choice.depth.is_some()),
                    (
                        "initiate.start.heading_spread",
                        choice.heading_spread_deg.is_some(),
                    ),
                ] {
                    if given {
                        return Err(Error::parameter(
                            name,
                            "does not apply to a start file (initiate.start FILE); give initiate.start ground or air",
                        ));
                    }
                }
                Start::Given(StartState::read(std::path::Path::new(path), birds)?)
            }
        })
    }
}

impl StartRegion {
    /// Width and depth for `n` birds, wingspans: by default 4.5√N wide (at least 20) and half
    /// as deep, 10 to 15 wingspans, wider where random packing needs it (more than about 300
    /// birds 1.5 apart).
    pub fn size(&self, n: usize) -> (f64, f64) {
        let auto = (AIR_WIDTH_PER_ROOT_BIRD * (n as f64).sqrt()).max(AIR_MIN_WIDTH);
        let (lo, hi) = AIR_DEPTH_RANGE;
        let depth = self
            .depth
            .unwrap_or((0.5 * self.width.unwrap_or(auto)).clamp(lo, hi));
        // Wide enough for random packing (about half the area) with a tenth to spare, as the
        // take-off area: 1000 birds 1.5 apart need 259 × 15 wingspans.
        let packing = 1.1 * n as f64 * PI / 4.0 * self.min_spacing * self.min_spacing / 0.5;
        let w = self
            .width
            .unwrap_or_else(|| auto.max(packing / depth.max(1e-9)));
        (w, depth)
    }
}

/// A start file: world-frame positions (wingspans), optional headings (radians clockwise from +y)
/// and speeds (wingspans per second), one entry per bird.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartState {
    /// East, wingspans.
    pub x: Vec<f64>,
    /// North, wingspans.
    pub y: Vec<f64>,
    /// Headings, radians clockwise from +y (default: the cruise heading).
    #[serde(default)]
    pub heading: Option<Vec<f64>>,
    /// Speeds, wingspans per second (default: the minimum speed).
    #[serde(default)]
    pub speed: Option<Vec<f64>>,
}

impl StartState {
    /// The formation its birds fly and how the others join it, flying along `heading`
    /// (radians clockwise from +y; [`Joining::of`]).
    pub fn joining(&self, heading: f64) -> Option<Joining> {
        let pos: Vec<DVec2> = self
            .x
            .iter()
            .zip(&self.y)
            .map(|(&x, &y)| DVec2::new(x, y))
            .collect();
        Joining::of(&pos, heading)
    }

    /// Reads and checks a start file for `birds` birds.
    pub fn read(path: &Path, birds: usize) -> Result<StartState> {
        let s: StartState = crate::io::read_json(path)?;
        let mut arrays: Vec<(&str, &Vec<f64>)> = vec![("x", &s.x), ("y", &s.y)];
        if let Some(h) = &s.heading {
            arrays.push(("heading", h));
        }
        if let Some(v) = &s.speed {
            arrays.push(("speed", v));
        }
        for (name, a) in arrays {
            if a.len() != birds {
                return Err(Error::format(
                    path,
                    format!(
                        "{name}: {} values, but the steady flight has {birds} birds",
                        a.len()
                    ),
                ));
            }
            if let Some(i) = a.iter().position(|v| !v.is_finite()) {
                return Err(Error::format(
                    path,
                    format!("{name}[{i}]: not a finite number"),
                ));
            }
        }
        if let Some(v) = &s.speed {
            if let Some(i) = v.iter().position(|v| *v <= 0.0) {
                return Err(Error::format(path, format!("speed[{i}]: must be positive")));
            }
        }
        // Where an animation file may hold a bird: one 10¹² wingspans away made the take-off's
        // neighbour grid crawl (75 s), one at 10³⁰⁰ overflowed it (a panic).
        let bound = crate::limits::MAX_COORDINATE;
        for (name, a) in [("x", &s.x), ("y", &s.y)] {
            if let Some(i) = a.iter().position(|v| v.abs() > bound) {
                return Err(Error::format(
                    path,
                    format!(
                        "{name}[{i}]: {:e} wingspans; a start position must be within ±{bound:e} wingspans",
                        a[i]
                    ),
                ));
            }
        }
        if let Some((j, i, d)) = closest_pair_below(&s.x, &s.y, START_MIN_SEPARATION) {
            return Err(Error::format(
                path,
                if d == 0.0 {
                    format!(
                        "birds {j} and {i} start at the same position ({}, {})",
                        s.x[i], s.y[i]
                    )
                } else {
                    format!(
                        "birds {j} and {i} start {d:.2e} wingspans apart, closer than {START_MIN_SEPARATION} wingspans: their bodies overlap; move them apart"
                    )
                },
            ));
        }
        Ok(s)
    }
}

/// A start file's bird at most this far from the bird ahead of it on an arm flies in the
/// formation (is *formed*), wingspans: a wide spacing for a V (real neighbours are about 0.8
/// apart, a straggler 3) and far nearer than a bird still flying in (the late birds of a filmed
/// joining were 30 aside). The paper is silent; docs/initiation.md, "Joining".
pub const FORMED_REACH: f64 = 4.0;

/// A formed bird is at least this far behind, and this far farther out to the side than, the bird
/// ahead of it on its arm, wingspans (a line of birds abreast or in file is not an arm).
pub const FORMED_STEP: f64 = 0.1;

/// How the birds of a start file make the formation they join: the birds already flying it
/// (*formed*: the leader and, on each arm, a chain of birds each within [`FORMED_REACH`] of the
/// bird ahead of it, behind it and farther out) keep their arm and their order; every other
/// bird (*late*) takes the free end of the arm whose last formed bird is nearest to it, behind
/// that bird, the nearest first (in order of arrival).
#[derive(Debug, Clone, PartialEq)]
pub struct Joining {
    /// The leading bird (the front-most bird with a neighbour within [`FORMED_REACH`]).
    pub leader: usize,
    /// `arms[0]` left, `arms[1]` right: birds from the leader outwards, the formed ones first.
    pub arms: [Vec<usize>; 2],
    /// Formed birds on each arm (the first this many of `arms[k]`).
    pub formed: [usize; 2],
    /// Each bird's offset to the right of the leader across the heading, wingspans.
    pub lateral: Vec<f64>,
}

impl Joining {
    /// The joining of birds at `pos` (wingspans) flying along `heading` (radians clockwise from
    /// +y), or `None` when no bird has a formed follower (birds scattered, not a formation: the
    /// flock forms its own).
    pub fn of(pos: &[DVec2], heading: f64) -> Option<Joining> {
        let n = pos.len();
        if n < 2 {
            return None;
        }
        let dc = perception::direction(heading);
        let rc = perception::right_of(heading);
        let along: Vec<f64> = pos.iter().map(|p| p.dot(dc)).collect();
        let across: Vec<f64> = pos.iter().map(|p| p.dot(rc)).collect();
        let near = |i: usize| (0..n).any(|j| j != i && (pos[j] - pos[i]).length() <= FORMED_REACH);
        let leader = (0..n)
            .filter(|&i| near(i))
            .max_by(|&a, &b| along[a].total_cmp(&along[b]).then(b.cmp(&a)))?;
        let lateral: Vec<f64> = across.iter().map(|a| a - across[leader]).collect();
        let mut taken = vec![false; n];
        taken[leader] = true;
        let mut arms: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        for (k, arm) in arms.iter_mut().enumerate() {
            let side = if k == 0 { -1.0 } else { 1.0 };
            let mut tail = leader;
            loop {
                let next = (0..n)
                    .filter(|&c| !taken[c])
                    .filter(|&c| {
                        side * lateral[c] >= side * lateral[tail] + FORMED_STEP
                            && along[tail] - along[c] >= FORMED_STEP
                            && (pos[c] - pos[tail]).length() <= FORMED_REACH
                    })
                    .min_by(|&a, &b| {
                        (pos[a] - pos[tail])
                            .length()
                            .total_cmp(&(pos[b] - pos[tail]).length())
                            .then(a.cmp(&b))
                    });
                match next {
                    Some(c) => {
                        taken[c] = true;
                        arm.push(c);
                        tail = c;
                    }
                    None => break,
                }
            }
        }
        if arms[0].is_empty() && arms[1].is_empty() {
            return None;
        }
        let formed = [arms[0].len(), arms[1].len()];
        let tails = arms.clone().map(|a| a.last().copied().unwrap_or(leader));
        // Late birds: to the arm whose tail is nearer (ties to the shorter arm), in order of
        // their distance to it.
        let mut late: [Vec<(f64, usize)>; 2] = [Vec::new(), Vec::new()];
        for c in (0..n).filter(|&c| !taken[c]) {
            let d = tails.map(|t| (pos[c] - pos[t]).length());
            let k = match d[0].total_cmp(&d[1]) {
                std::cmp::Ordering::Less => 0,
                std::cmp::Ordering::Greater => 1,
                std::cmp::Ordering::Equal => usize::from(formed[1] < formed[0]),
            };
            late[k].push((d[k], c));
        }
        for (k, l) in late.iter_mut().enumerate() {
            l.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            arms[k].extend(l.iter().map(|&(_, c)| c));
        }
        Some(Joining {
            leader,
            arms,
            formed,
            lateral,
        })
    }

    /// Birds in key-shape order (left to right: the left arm from its tail inwards, the leader,
    /// the right arm outwards).
    pub fn order(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self.arms[0].iter().rev().copied().collect();
        v.push(self.leader);
        v.extend(self.arms[1].iter().copied());
        v
    }

    /// Whether bird `b` is formed.
    pub fn is_formed(&self, b: usize) -> bool {
        b == self.leader || (0..2).any(|k| self.arms[k][..self.formed[k]].contains(&b))
    }

    /// The formation the key shapes are solved for: the birds left of the leader and the
    /// lateral gaps between key-shape neighbours that were both formed (the others drawn).
    pub fn given_arms(&self) -> crate::keyshape::given::GivenArms {
        let order = self.order();
        let gaps = order
            .windows(2)
            .map(|w| {
                (self.is_formed(w[0]) && self.is_formed(w[1]))
                    .then(|| (self.lateral[w[1]] - self.lateral[w[0]]).abs())
            })
            .collect();
        crate::keyshape::given::GivenArms {
            left: self.arms[0].len(),
            gaps,
        }
    }

    /// The slot of every bird in `target` and the leader: the leader's slot to the leader, and
    /// each arm's slots from the leader outwards to the arm's birds in order; `None` when the
    /// target's arms have other lengths (a steady flight made for another formation).
    pub fn slots(&self, target: &TargetShape) -> Option<(Vec<usize>, usize)> {
        let n = self.lateral.len();
        if target.len() != n || (0..2).any(|k| target.arms[k].len() != self.arms[k].len()) {
            return None;
        }
        let mut slot = vec![target.leader; n];
        for k in 0..2 {
            for (&b, &s) in self.arms[k].iter().zip(&target.arms[k]) {
                slot[b] = s;
            }
        }
        Some((slot, self.leader))
    }
}

impl Start {
    /// With a start file whose birds already fly a formation, the slot of every bird in
    /// `target` and the leader by [`Joining`]: `None` for other starts, birds scattered, or a
    /// target of another formation (the birds then take slots in order across the heading).
    pub fn given_slots(
        &self,
        target: &TargetShape,
        pos: &[DVec2],
        heading: f64,
    ) -> Option<(Vec<usize>, usize)> {
        match self {
            Start::Given(_) => Joining::of(pos, heading)?.slots(target),
            _ => None,
        }
    }
}

/// Two birds of a start file closer than this, wingspans, overlap (a goose's body is about a
/// fifth of its span across, so two bodies a tenth of a span apart already touch).
pub const START_MIN_SEPARATION: f64 = 0.1;

/// The first pair `(j, i, distance)`, `j < i`, of points `(x, y)` closer than `min` (in the
/// order of `i`, then the closest `j`), found by a sweep along x: O(n log n) for spread points.
fn closest_pair_below(x: &[f64], y: &[f64], min: f64) -> Option<(usize, usize, f64)> {
    let mut order: Vec<usize> = (0..x.len()).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    let mut found: Option<(usize, usize, f64)> = None;
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if x[b] - x[a] >= min {
                break;
            }
            let d = (x[b] - x[a]).hypot(y[b] - y[a]);
            if d < min {
                let pair = (a.min(b), a.max(b), d);
                let better = match found {
                    None => true,
                    Some((j, i, e)) => (pair.1, pair.2, pair.0) < (i, e, j),
                };
                if better {
                    found = Some(pair);
                }
            }
        }
    }
    found
}

/// Random start positions, headings and speeds (wingspans, radians, wingspans per second):
/// positions uniform in the region at least `min_spacing` apart; headings uniform within the
/// spread and speeds between the minimum and the cruise speed, redrawn while two birds would,
/// flying straight, come closer than [`START_MISS`] within [`START_HORIZON`] (no start on a
/// collision course: the birds turn round at once, and a pair that close has no room to).
pub fn random_start(
    n: usize,
    region: &StartRegion,
    params: &StepParams,
    rng: &mut impl Rng,
) -> Result<(Vec<DVec2>, Vec<f64>, Vec<f64>)> {
    scatter(n, region, params, START_MISS, START_HORIZON, rng)
}

/// [`random_start`] with the predicted miss distance (wingspans) a start heading must keep from
/// the birds drawn before it within `horizon` seconds (the ground start's positions are drawn
/// with the avoidance distance and a quarter turn's time).
fn scatter(
    n: usize,
    region: &StartRegion,
    params: &StepParams,
    miss: f64,
    horizon: f64,
    rng: &mut impl Rng,
) -> Result<(Vec<DVec2>, Vec<f64>, Vec<f64>)> {
    let (w, d) = region.size(n);
    let dc = perception::direction(params.cruise_heading);
    let rc = perception::right_of(params.cruise_heading);
    let mut pos: Vec<DVec2> = Vec::with_capacity(n);
    let attempts = 2000 * n.max(1);
    let mut tries = 0;
    // Rejection sampling on a grid of cells of the minimum spacing keeps this O(n).
    let cell = region.min_spacing.max(1e-9);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> =
        std::collections::HashMap::new();
    let key = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    while pos.len() < n {
        tries += 1;
        if tries > attempts {
            return Err(Error::parameter(
                "initiate.start.random.width/initiate.start.random.depth",
                format!(
                    "cannot place {n} birds {} wingspans apart in a {w:.1} × {d:.1} wingspan region; make it larger",
                    region.min_spacing
                ),
            ));
        }
        let a: f64 = rng.random_range(-0.5..0.5);
        let b: f64 = rng.random_range(-0.5..0.5);
        let p = rc * (a * w) + dc * (b * d);
        let (kx, ky) = key(p);
        let clash = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                grid.get(&(kx.saturating_add(dx), ky.saturating_add(dy)))
                    .is_some_and(|v| {
                        v.iter()
                            .any(|&j| (pos[j] - p).length() < region.min_spacing)
                    })
            })
        });
        if clash {
            continue;
        }
        grid.entry((kx, ky)).or_default().push(pos.len());
        pos.push(p);
    }
    // Headings and speeds: no two birds start on a course that brings them closer than the
    // avoidance distance before they could turn a quarter circle away (straight-line
    // prediction); a draw that does is redrawn, up to START_DRAWS times (then the safest is kept).
    let want_miss = params.opts.avoid_distance.max(miss);
    let mut heading: Vec<f64> = Vec::with_capacity(n);
    let mut speed: Vec<f64> = Vec::with_capacity(n);
    for i in 0..n {
        let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
        for _ in 0..START_DRAWS {
            let h = if region.heading_spread > 0.0 {
                rng.random_range(-region.heading_spread..=region.heading_spread)
            } else {
                0.0
            };
            let h = sim::wrap_angle(params.cruise_heading + h);
            let v = rng.random_range(params.min_speed..=params.cruise_speed);
            let vel = perception::direction(h) * v;
            let miss = (0..i)
                .map(|j| {
                    let dp = pos[j] - pos[i];
                    let dv = perception::direction(heading[j]) * speed[j] - vel;
                    let vv = dv.length_squared();
                    let tau = if vv > 0.0 {
                        (-dp.dot(dv) / vv).clamp(0.0, horizon)
                    } else {
                        0.0
                    };
                    (dp + dv * tau).length()
                })
                .fold(f64::INFINITY, f64::min);
            if miss > best.0 {
                best = (miss, h, v);
            }
            if miss >= want_miss {
                break;
            }
        }
        heading.push(best.1);
        speed.push(best.2);
    }
    Ok((pos, heading, speed))
}

/// A take-off area: positions uniform in the plan's rectangle at least `min_spacing` apart, at
/// rest (speed 0, z = 0), facing within the spread of the cruise heading, with departure times
/// front to back over the stagger window (the front-most bird leaves at 0 and leads; a small
/// random jitter of a tenth of the window mixes neighbours). With assigned slots the simulation
/// hands these times out again by slot depth ([`Simulation::new`]). An area too small for the
/// flock is an error naming the option paths.
pub fn ground_start(
    n: usize,
    g: &GroundStart,
    plan: &TakeoffPlan,
    params: &StepParams,
    rng: &mut impl Rng,
) -> Result<(Vec<DVec2>, Vec<f64>, Vec<f64>)> {
    let (w, d) = (plan.width, plan.depth);
    // Random packing of discs reaches about half the area (random sequential adsorption: 0.547).
    let capacity = 0.5 * w * d / (PI / 4.0 * g.min_spacing * g.min_spacing);
    if (n as f64) > capacity.max(1.0) {
        let need = (n as f64 * PI / 4.0 * g.min_spacing * g.min_spacing / 0.5).sqrt();
        return Err(Error::parameter(
            "initiate.start.ground.width/initiate.start.ground.depth",
            format!(
                "a take-off area of {w:.1} × {d:.1} wingspans is too small for {n} birds {} wingspans apart; give at least about {need:.0} × {need:.0}",
                g.min_spacing
            ),
        ));
    }
    let region = StartRegion {
        width: Some(w),
        depth: Some(d),
        heading_spread: 0.0,
        min_spacing: g.min_spacing,
    };
    let quarter_turn = std::f64::consts::FRAC_PI_2 / params.opts.max_turn_rate;
    let (pos, _, _) = scatter(
        n,
        &region,
        params,
        params.opts.avoid_distance,
        quarter_turn,
        rng,
    )?;
    let heading: Vec<f64> = (0..n)
        .map(|_| {
            let h = if g.heading_spread > 0.0 {
                rng.random_range(-g.heading_spread..=g.heading_spread)
            } else {
                0.0
            };
            sim::wrap_angle(params.cruise_heading + h)
        })
        .collect();
    let dc = perception::direction(params.cruise_heading);
    let along: Vec<f64> = pos.iter().map(|p| p.dot(dc)).collect();
    let front = along.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = (front - along.iter().copied().fold(f64::INFINITY, f64::min)).max(1e-9);
    let w = plan.stagger;
    let depart: Vec<f64> = along
        .iter()
        .map(|&a| {
            let jitter: f64 = rng.random_range(0.0..1.0);
            if a >= front {
                0.0
            } else {
                w * (0.9 * (front - a) / span + 0.1 * jitter)
            }
        })
        .collect();
    Ok((pos, heading, depart))
}

/// The simulation at its first instant: parameters for the cruise, the visual field widened for
/// `target` if asked, and the start (random ones drawn from `rng`). Also gives the take-off plan.
pub fn start_simulation(
    target: &TargetShape,
    cruise: &Cruise,
    opts: &InitiateOptions,
    rng: &mut impl Rng,
) -> Result<(Simulation, TakeoffPlan)> {
    opts.validate()?;
    if !(cruise.speed.is_finite() && cruise.speed > 0.0 && cruise.heading.is_finite()) {
        return Err(Error::parameter(
            "cruise speed",
            "the leader's speed must be a positive number",
        ));
    }
    if !(cruise.wingspan_m.is_finite() && cruise.wingspan_m > 0.0) {
        return Err(Error::parameter(
            "wingspan_m",
            "must be a positive number of metres",
        ));
    }
    let n = target.len();
    let plan = TakeoffPlan::new(n, opts, cruise);
    let mut params = opts.plan_params(cruise, &plan);
    if opts.widen_field {
        let field = &mut std::sync::Arc::make_mut(&mut params.opts)
            .perception
            .fov_per_eye;
        *field = field.max(target.required_field(FIELD_MARGIN));
    }
    if opts.hold >= opts.max_time {
        return Err(Error::parameter(
            "initiate.hold",
            format!(
                "{} s: the flock must hold its formation for longer than the whole time limit of {} s (initiate.max_time); give a shorter hold or a longer limit",
                opts.hold, opts.max_time
            ),
        ));
    }
    let alt = opts.cruise_altitude;
    let (pos, z, heading, speed, depart) = match &opts.start {
        Start::Ground(g) => {
            let (pos, heading, depart) = ground_start(n, g, &plan, &params, rng)?;
            // The flock sits for `ground_seconds` before the first run starts.
            let first = depart.iter().copied().fold(f64::INFINITY, f64::min);
            let first = if first.is_finite() { first } else { 0.0 };
            let depart: Vec<f64> = depart
                .iter()
                .map(|d| d - first + opts.ground_seconds)
                .collect();
            check_climb(opts, &params, plan.climb_drive, &depart)?;
            (pos, vec![0.0; n], heading, vec![0.0; n], depart)
        }
        Start::Random(region) => {
            let (pos, heading, speed) = random_start(n, region, &params, rng)?;
            (pos, vec![alt; n], heading, speed, vec![0.0; n])
        }
        Start::Given(s) => {
            if s.x.len() != n || s.y.len() != n {
                return Err(Error::parameter(
                    "initiate.start",
                    format!("{} start positions for {n} birds", s.x.len()),
                ));
            }
            check_reach(s, params.max_speed, opts.max_time)?;
            let pos =
                s.x.iter()
                    .zip(&s.y)
                    .map(|(&x, &y)| DVec2::new(x, y))
                    .collect();
            let heading = s.heading.clone().unwrap_or_else(|| vec![cruise.heading; n]);
            let speed = match &s.speed {
                Some(v) => v
                    .iter()
                    .map(|v| v.clamp(params.min_speed, params.max_speed))
                    .collect(),
                None => vec![params.min_speed; n],
            };
            (pos, vec![alt; n], heading, speed, vec![0.0; n])
        }
    };
    let mut sim = Simulation::new(target.clone(), params, pos, z, heading, speed, depart);
    if matches!(opts.start, Start::Random(_)) {
        sim.scatter_heights(AIR_HEIGHT_BAND, rng);
        sim.separate_heights(AIR_HEIGHT_BAND, rng);
    }
    Ok((sim, plan))
}

/// Share of the climb the time limit allows that a take-off may need: the rest is left for the
/// run-up, the levelling off and settling into the slots (our choice; a cruise altitude just
/// under the bare climb limit ran the whole take-off and ended without converging).
const CLIMB_BUDGET_SHARE: f64 = 0.9;

/// Refuses a ground take-off that cannot reach the cruise altitude and then hold the formation
/// for `initiate.hold` within the time limit: the last bird leaves the ground at the latest of
/// `depart`, climbs at most `params.climb_rate` and must be level, in its slot, `hold` seconds
/// before the limit. Decided before the simulation, so an impossible request costs nothing.
fn check_climb(
    opts: &InitiateOptions,
    params: &StepParams,
    drive: f64,
    depart: &[f64],
) -> Result<()> {
    let last = depart.iter().copied().fold(0.0f64, f64::max);
    let budget = opts.max_time - opts.hold - last;
    if budget <= 0.0 {
        return Err(Error::parameter(
            "initiate.hold",
            format!(
                "{} s: the last bird starts its take-off run {last:.1} s in, so holding the formation that long leaves no time to climb and form up within the time limit of {} s (initiate.max_time); give a shorter hold or a longer limit",
                opts.hold, opts.max_time
            ),
        ));
    }
    let reach =
        CLIMB_BUDGET_SHARE * reachable_altitude(params.climb_rate, params.vertical_accel, budget);
    if opts.cruise_altitude > reach {
        return Err(Error::parameter(
            "initiate.cruise_altitude",
            format!(
                "{} wingspans cannot be reached: climbing at most {:.3} wingspans/s (initiate.climb_rate, times the take-off's drive {drive:.2}) from the last take-off run at {last:.1} s, and holding the formation for {} s (initiate.hold), the birds reach at most about {:.0} wingspans within the time limit of {} s (initiate.max_time)",
                opts.cruise_altitude,
                params.climb_rate,
                opts.hold,
                reach.floor(),
                opts.max_time
            ),
        ));
    }
    Ok(())
}

/// Refuses a start file with a bird farther from the flock's middle (the median position) than
/// it can fly within the time limit `max_time` at `max_speed` (wingspans per second): the
/// take-off would run to the limit and fail to converge, as a distant bird did after a 300 s run.
fn check_reach(s: &StartState, max_speed: f64, max_time: f64) -> Result<()> {
    let median = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    if s.x.is_empty() {
        return Ok(());
    }
    let (mx, my) = (median(&s.x), median(&s.y));
    let reach = max_speed * max_time;
    let far = (0..s.x.len())
        .map(|i| (i, (s.x[i] - mx).hypot(s.y[i] - my)))
        .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)));
    match far {
        Some((i, d)) if d > reach => Err(Error::parameter(
            "initiate.start",
            format!(
                "the start file's bird {i} is at ({}, {}), {d:.3e} wingspans from the middle of the flock ({mx}, {my}): more than the {reach:.0} wingspans it can fly within the time limit of {max_time} s; move it closer",
                s.x[i], s.y[i]
            ),
        )),
        _ => Ok(()),
    }
}

/// The highest altitude a bird climbing from the ground at most `climb_rate` (wingspans per
/// second, reached and shed at `vertical_accel`, wingspans per second squared) can reach and
/// level off at within `seconds`: w (T − w/a), or a T²/4 when it never reaches the full rate.
pub fn reachable_altitude(climb_rate: f64, vertical_accel: f64, seconds: f64) -> f64 {
    let (w, a, t) = (climb_rate, vertical_accel, seconds);
    if t >= 2.0 * w / a {
        w * (t - w / a)
    } else {
        a * t * t / 4.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_pair_below_the_bound_is_found_by_the_sweep() {
        let x = [0.0, 5.0, 1.0, 5.05, 9.0, 1.0];
        let y = [0.0, 0.0, 3.0, 0.0, 0.0, 3.0];
        // Birds 2 and 5 coincide; 1 and 3 are 0.05 apart: the pair with the lower second index
        // comes first.
        let (j, i, d) = closest_pair_below(&x, &y, 0.1).unwrap();
        assert_eq!((j, i), (1, 3));
        assert!((d - 0.05).abs() < 1e-12, "{d}");
        assert_eq!(closest_pair_below(&x[..5], &y[..5], 0.01), None);
        assert_eq!(closest_pair_below(&x, &y, 0.01), Some((2, 5, 0.0)));
        // Against the brute force on a grid with near neighbours.
        let n = 200;
        let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(7);
        let xs: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..20.0)).collect();
        let ys: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..20.0)).collect();
        let d = |(j, i): (usize, usize)| (xs[i] - xs[j]).hypot(ys[i] - ys[j]);
        let brute = (0..n)
            .flat_map(|i| (0..i).map(move |j| (j, i)))
            .filter(|&p| d(p) < 0.5)
            .min_by(|&a, &b| {
                a.1.cmp(&b.1)
                    .then(d(a).total_cmp(&d(b)))
                    .then(a.0.cmp(&b.0))
            });
        assert!(brute.is_some());
        assert_eq!(closest_pair_below(&xs, &ys, 0.5).map(|p| (p.0, p.1)), brute);
    }
}
