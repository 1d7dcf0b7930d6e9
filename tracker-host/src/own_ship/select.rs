//! One source per quantity. A bridge network carries the same quantity from several
//! talkers (a real one: five `VHW` talkers and two `VTG`s 1 kn apart); feeding them all to
//! one filter would average instruments that disagree. Per quantity (position, velocity
//! over ground, heading, speed through the water) one talker is chosen and the others are
//! ignored; when two disagree the disagreement is reported once per pair.
//!
//! The choice: the first talker of the operator's priority list (`--nmea-source
//! heading=HE,GP`) that is delivering; without a list, the first talker heard, but the AIS
//! transponder (`AI`, its `VDO` reports) gives way to another talker delivering (heard
//! twice within [`SILENT_S`]) and dated with it (not more than [`SILENT_S`] before its
//! last report): its position is from its internal GNSS receiver, there for its own
//! reports, and its heading from a sensor the bridge sends as well. A chosen talker silent
//! for [`SILENT_S`] gives way to the next one heard. A talker whose readings are dated more
//! than [`SILENT_S`] before the chosen one's last is not taken, told once (a log of another
//! voyage played beside a capture whose untimed `VDO`s take the scans' time). The
//! operator's list, when given, decides alone.

use std::collections::BTreeMap;

use super::sentences::{Quantity, Reading};

/// A chosen talker silent this long gives way, s.
pub const SILENT_S: f64 = 10.0;

/// The AIS transponder's talker: chosen only while no other talker delivers.
pub const AIS_TALKER: &str = "AI";

/// Two readings this close in time are compared, s.
const COMPARE_WITHIN_S: f64 = 2.0;

/// How far two talkers may differ before it is reported.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Position, m.
    pub position_m: f64,
    /// Speed (over ground or through the water), m/s.
    pub speed_mps: f64,
    /// Course or heading, degrees.
    pub angle_deg: f64,
}

impl Default for Tolerances {
    /// 50 m, 0.5 kn, 5°.
    fn default() -> Self {
        Tolerances {
            position_m: 50.0,
            speed_mps: 0.257,
            angle_deg: 5.0,
        }
    }
}

/// The last reading of one talker for one quantity, reduced to comparable numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Last {
    time_s: f64,
    value: Value,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Value {
    /// Local east, north, m.
    Position([f64; 2]),
    /// Speed, m/s, and an angle (course or heading), degrees, when there is one.
    Motion(f64, Option<f64>),
    /// A heading, degrees true.
    Angle(f64),
}

/// The per-quantity choice of talker.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selector {
    priority: BTreeMap<Quantity, Vec<String>>,
    chosen: BTreeMap<Quantity, (String, f64)>,
    last: BTreeMap<(Quantity, String), Last>,
    reported: Vec<(Quantity, String, String)>,
    tolerances: Tolerances,
    events: crate::event_log::EventLog,
    disagreements: u64,
    /// The talker last told as each quantity's source: the first choice after
    /// [`Selector::forget_times`] is told only when it is another.
    told: BTreeMap<Quantity, String>,
    /// The talkers told once to be dated long before the chosen one, per quantity.
    dated_before_told: std::collections::BTreeSet<(Quantity, String)>,
}

impl Selector {
    /// Chooses by `priority` where given (talkers in order, per quantity), else the first
    /// heard.
    pub fn new(priority: BTreeMap<Quantity, Vec<String>>) -> Self {
        Selector {
            priority,
            ..Selector::default()
        }
    }

    /// Forgets the talkers' times (chosen and last heard), keeping the priorities, events
    /// and disagreement counts: the times were on a clock the bridge's UTC has replaced.
    pub fn forget_times(&mut self) {
        self.chosen.clear();
        self.last.clear();
    }

    /// The talker chosen for `q`, if any.
    pub fn chosen(&self, q: Quantity) -> Option<&str> {
        self.chosen.get(&q).map(|(t, _)| t.as_str())
    }

    /// Changes of source and disagreements, oldest first.
    pub fn events(&self) -> Vec<String> {
        self.events.lines("own-ship source")
    }

    /// Disagreements found (each pair reported once).
    pub fn disagreements(&self) -> u64 {
        self.disagreements
    }

    /// Whether `talker`'s `reading` at `now_s` is the one to use; `east_north` is its position
    /// in the local frame when it is a position. Notes the reading for comparison either way.
    pub fn admit(
        &mut self,
        talker: &str,
        reading: &Reading,
        east_north: Option<[f64; 2]>,
        now_s: f64,
    ) -> bool {
        let Some(q) = reading.quantity() else {
            return true;
        };
        // When this talker was heard before, for the AIS transponder's rule.
        let before_s = self.last.get(&(q, talker.to_string())).map(|l| l.time_s);
        let value = match (reading, east_north) {
            (Reading::Position { .. }, Some(p)) => Value::Position(p),
            (Reading::GroundVelocity { sog_mps, cog_deg }, _) => Value::Motion(*sog_mps, *cog_deg),
            (Reading::GroundSpeedAlongKeel(v) | Reading::WaterSpeed(v), _) => {
                Value::Motion(*v, None)
            }
            (Reading::HeadingTrue(h), _) => Value::Angle(*h),
            _ => Value::Motion(f64::NAN, None),
        };
        self.last.insert(
            (q, talker.to_string()),
            Last {
                time_s: now_s,
                value,
            },
        );
        let delivering = before_s.is_some_and(|b| now_s - b <= SILENT_S);
        let take = self.choose(q, talker, now_s, delivering);
        if take {
            self.chosen.insert(q, (talker.to_string(), now_s));
        } else {
            self.compare(q, talker);
        }
        take
    }

    /// Whether `talker` is to be used for `q` now; `delivering`: it was heard within
    /// [`SILENT_S`] before this reading.
    fn choose(&mut self, q: Quantity, talker: &str, now_s: f64, delivering: bool) -> bool {
        let current = self.chosen.get(&q).cloned();
        if let Some(list) = self.priority.get(&q) {
            let rank = |t: &str| list.iter().position(|x| x == t);
            let Some(mine) = rank(talker) else {
                return false;
            };
            let beaten = list[..mine].iter().any(|better| {
                self.last
                    .get(&(q, better.clone()))
                    .is_some_and(|l| now_s - l.time_s <= SILENT_S)
            });
            if !beaten && current.as_ref().is_some_and(|(c, _)| c != talker) {
                self.tell(q, talker, format!("{} source: talker {talker}", q.name()));
            }
            return !beaten;
        }
        match current {
            None => {
                if self.told.get(&q).is_none_or(|t| t != talker) {
                    self.tell(q, talker, format!("{} source: talker {talker}", q.name()));
                }
                true
            }
            Some((c, _)) if c == talker => true,
            // A talker heard once and then silent would flip the choice back and forth with
            // a steady transponder: it must be delivering.
            // … and delivering now: readings dated well before the transponder's last (a
            // log of another voyage beside a capture's untimed `VDO`s) took the choice back
            // with each of its readings, and lost it to the transponder's next (the 4G's
            // log beside the Garmin's capture: over a hundred such events in 31 scans).
            Some((c, last_s)) if c == AIS_TALKER && delivering && now_s + SILENT_S >= last_s => {
                let event = format!(
                    "{} source: talker {talker} (not the AIS transponder's {c})",
                    q.name()
                );
                self.tell(q, talker, event);
                true
            }
            Some((c, last_s)) if now_s - last_s > SILENT_S => {
                let event = format!(
                    "{} source: talker {c} silent for {:.0} s, now talker {talker}",
                    q.name(),
                    now_s - last_s
                );
                self.tell(q, talker, event);
                true
            }
            Some((c, last_s)) if now_s + SILENT_S < last_s => {
                if self.dated_before_told.insert((q, talker.to_string())) {
                    self.events.push(format!(
                        "{} source: talker {talker}'s readings are dated {:.0} s before {c}'s: not taken (another voyage's log, or a clock far off)",
                        q.name(),
                        last_s - now_s
                    ));
                }
                false
            }
            Some(_) => false,
        }
    }

    /// Tells `event`, a change of `q`'s source to `talker`, and notes it as told.
    fn tell(&mut self, q: Quantity, talker: &str, event: String) {
        self.events.push(event);
        self.told.insert(q, talker.to_string());
    }

    fn compare(&mut self, q: Quantity, other: &str) {
        let Some((chosen, _)) = self.chosen.get(&q).cloned() else {
            return;
        };
        let (Some(a), Some(b)) = (
            self.last.get(&(q, chosen.clone())).copied(),
            self.last.get(&(q, other.to_string())).copied(),
        ) else {
            return;
        };
        if (a.time_s - b.time_s).abs() > COMPARE_WITHIN_S {
            return;
        }
        let tol = self.tolerances;
        let angle = |x: f64, y: f64| ((x - y + 180.0).rem_euclid(360.0) - 180.0).abs();
        let differs = match (a.value, b.value) {
            (Value::Position(p), Value::Position(r)) => {
                let d = (p[0] - r[0]).hypot(p[1] - r[1]);
                (d > tol.position_m).then(|| format!("{d:.0} m apart"))
            }
            (Value::Motion(s, c), Value::Motion(t, d)) => {
                if (s - t).abs() > tol.speed_mps {
                    Some(format!(
                        "{:.1} kn against {:.1} kn",
                        s / 0.514_444,
                        t / 0.514_444
                    ))
                } else {
                    match (c, d) {
                        (Some(c), Some(d)) if s > 0.5 && angle(c, d) > tol.angle_deg => {
                            Some(format!("courses {c:.0}° and {d:.0}°"))
                        }
                        _ => None,
                    }
                }
            }
            (Value::Angle(h), Value::Angle(k)) => {
                (angle(h, k) > tol.angle_deg).then(|| format!("{h:.1}° against {k:.1}°"))
            }
            _ => None,
        };
        let Some(what) = differs else {
            return;
        };
        let key = (q, chosen.clone(), other.to_string());
        if !self.reported.contains(&key) {
            self.disagreements += 1;
            self.events.push(format!(
                "{} sources disagree: {chosen} (used) and {other} (ignored), {what}",
                q.name()
            ));
            self.reported.push(key);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sog(kn: f64) -> Reading {
        Reading::GroundVelocity {
            sog_mps: kn * 0.514_444,
            cog_deg: Some(242.0),
        }
    }

    #[test]
    fn one_talker_per_quantity_and_disagreements_reported_once() {
        let mut s = Selector::default();
        // The real network: BM VTG at 0.00 kn, BO VTG at 1.09 kn.
        assert!(s.admit("BM", &sog(0.0), None, 0.0));
        assert!(!s.admit("BO", &sog(1.09), None, 0.2));
        assert!(s.admit("BM", &sog(0.0), None, 1.0));
        assert!(!s.admit("BO", &sog(1.09), None, 1.2));
        assert_eq!(s.disagreements(), 1);
        assert!(s
            .events()
            .iter()
            .any(|e| e.contains("disagree") && e.contains("BM")));
        // BM falls silent: BO takes over after SILENT_S.
        assert!(!s.admit("BO", &sog(1.1), None, 5.0));
        assert!(s.admit("BO", &sog(1.1), None, 1.0 + SILENT_S + 0.5));
        assert_eq!(s.chosen(Quantity::GroundVelocity), Some("BO"));
        // Heading is a quantity of its own.
        assert!(s.admit("HE", &Reading::HeadingTrue(10.0), None, 12.0));
    }

    #[test]
    fn a_source_chosen_again_after_the_clock_is_replaced_is_not_told_again() {
        let mut s = Selector::default();
        let told = |s: &Selector| {
            s.events()
                .iter()
                .filter(|e| e.contains("velocity source: talker BM"))
                .count()
        };
        assert!(s.admit("BM", &sog(5.0), None, 0.0));
        assert_eq!(told(&s), 1);
        // The first date heard: the times forgotten, the same talker chosen again.
        s.forget_times();
        assert!(s.admit("BM", &sog(5.0), None, 1_000_000.0));
        assert_eq!(told(&s), 1, "{:?}", s.events());
        // Another talker first after the restart is told.
        s.forget_times();
        assert!(s.admit("GP", &sog(5.0), None, 2_000_000.0));
        assert!(s
            .events()
            .iter()
            .any(|e| e.contains("velocity source: talker GP")));
    }

    #[test]
    fn the_operators_priority_wins_while_it_delivers() {
        let mut p = BTreeMap::new();
        p.insert(Quantity::Heading, vec!["HE".to_string(), "AP".to_string()]);
        let mut s = Selector::new(p);
        let h = Reading::HeadingTrue(90.0);
        assert!(
            s.admit("AP", &h, None, 0.0),
            "the first on the list heard so far"
        );
        assert!(s.admit("HE", &h, None, 0.5));
        assert!(!s.admit("AP", &h, None, 1.0), "HE delivers: AP is not used");
        assert!(!s.admit("XX", &h, None, 1.0), "not on the list");
        assert!(s.admit("AP", &h, None, 20.0), "HE silent: AP again");
    }

    /// The AIS transponder's own reports (`AIVDO`) give way to a bridge sensor whichever is
    /// heard first, and are used only while no other talker delivers.
    #[test]
    fn the_ais_transponder_gives_way_to_the_bridges_sensors() {
        let mut s = Selector::default();
        assert!(s.admit("AI", &sog(5.0), None, 0.0), "the only talker heard");
        assert!(
            !s.admit("GP", &sog(5.1), None, 0.5),
            "heard once: not delivering yet"
        );
        assert!(
            s.admit("GP", &sog(5.1), None, 0.9),
            "GP takes over, delivering"
        );
        assert!(!s.admit("AI", &sog(5.0), None, 1.0));
        assert!(s.admit("GP", &sog(5.1), None, 1.5));
        assert_eq!(s.chosen(Quantity::GroundVelocity), Some("GP"));
        // GP silent: AI waits as long as any talker would, then stands in...
        assert!(!s.admit("AI", &sog(5.0), None, 5.0));
        assert!(s.admit("AI", &sog(5.0), None, 1.6 + SILENT_S));
        assert_eq!(s.chosen(Quantity::GroundVelocity), Some("AI"));
        // ...until GP delivers again (a second reading within SILENT_S).
        assert!(!s.admit("GP", &sog(5.1), None, 2.0 + SILENT_S));
        assert!(s.admit("GP", &sog(5.1), None, 3.0 + SILENT_S));
        assert!(!s.admit("AI", &sog(5.0), None, 3.5 + SILENT_S));
    }

    /// A talker whose readings are dated long before the transponder's (another voyage's
    /// log beside a capture's untimed `VDO`s) does not take the choice back from it.
    #[test]
    fn a_talker_dated_long_before_the_transponder_does_not_take_over() {
        let mut s = Selector::default();
        let now = 63_000_000.0;
        assert!(s.admit("AI", &sog(5.0), None, now));
        for k in 0..5 {
            let t = f64::from(k);
            assert!(!s.admit("GP", &sog(5.1), None, t), "reading at {t} s");
            assert!(s.admit("AI", &sog(5.0), None, now + 2.5 * t));
        }
        // Told once.
        assert_eq!(s.events().len(), 2, "{:?}", s.events());
        assert!(
            s.events()[1].contains("GP's readings are dated"),
            "{:?}",
            s.events()
        );
        // Dated with the transponder, it takes over as before.
        assert!(!s.admit("GP", &sog(5.1), None, now + 11.0));
        assert!(s.admit("GP", &sog(5.1), None, now + 12.0));
    }

    /// A talker that reports less often than every [`SILENT_S`] does not flip the choice
    /// back and forth with a steady transponder (two events a cycle, the position moving
    /// between two antennas).
    #[test]
    fn a_slow_talker_does_not_flip_the_transponder_back_and_forth() {
        let mut s = Selector::default();
        for k in 0..60 {
            let t = f64::from(k);
            s.admit("AI", &sog(5.0), None, t);
            if k % 12 == 0 {
                s.admit("GP", &sog(5.1), None, t + 0.5);
            }
        }
        assert_eq!(s.chosen(Quantity::GroundVelocity), Some("AI"));
        assert_eq!(s.events().len(), 1, "{:?}", s.events());
    }
}
