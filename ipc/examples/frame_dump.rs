//! The Rust client's reference answers for the Python client's tests and latency figures.
//!
//! ```text
//! frame_dump dump ROOT PREFIX SCRIPT     # run SCRIPT on a running daemon, print every result frame
//! frame_dump latency ROOT PREFIX [--bodies 100] [--frames 5000] [--warmup 500] [--budget-ns 1000000]
//! ```
//!
//! Both connect to the daemon serving `ROOT` under iceoryx2 prefix `PREFIX` and create a
//! scene of their own. **dump** builds the scene a script describes and publishes its pose
//! frames; for each it prints one JSON line: the result header (timing fields left out:
//! `elapsed_ns`, `stage_ns`, `budget_met`) and every record, floats as the hex of their
//! bits so a comparison is exact. `ipc/python/tests/test_rust_parity.py` runs the same
//! script through the Python client and compares record for record. **latency** measures
//! the round trip of `--bodies` spheres moving on a grid (the scene of
//! `examples/ipc_latency.rs`) and prints its percentiles as one JSON line;
//! `ipc/python/examples/latency.py` runs it beside the Python client.
//!
//! The script is one command per line (`#` starts a comment); ids are the daemon's, which
//! count from 0 in a fresh scene in the order of the script:
//!
//! ```text
//! shape sphere R | capsule R HH | cuboid HX HY HZ | cylinder R HH | cone R HH
//! convex N x y z ...              # N points
//! mesh NV NT x y z ... i j k ...  # NV vertices, NT triangles
//! body SHAPE MOTION GROUP MASK MARGIN x y z qx qy qz qw   # MOTION static|kinematic|dynamic, MARGIN or `default`
//! update BODY MOTION GROUP MASK MARGIN
//! remove BODY
//! broad CODE                      # a BroadPhaseCode value
//! frame SEQ BUDGET_NS QUERY_FLAGS N  # then N lines: pose BODY x y z qx qy qz qw
//! ```

use std::error::Error;
use std::fmt::Write as _;
use std::time::{Duration, Instant};

use iceoryx2::prelude::{LogLevel, ipc, set_log_level_from_env_or};
use proxima_ipc::client::{BodySpec, Client, ClientBuilder, Motion, Primitive};
use proxima_ipc::tools::latency::LatencyRecorder;
use proxima_ipc::tools::latency_scene;
use proxima_ipc::wire::{BroadPhaseCode, PoseRecord, ResultFrameHeader, ResultRecord, query};

/// How long a result frame is waited for.
const FRAME_TIMEOUT: Duration = Duration::from_secs(10);

fn main() -> Result<(), Box<dyn Error>> {
    set_log_level_from_env_or(LogLevel::Error);
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [mode, root, prefix, rest @ ..] if mode == "dump" && rest.len() == 1 => {
            let script = std::fs::read_to_string(&rest[0])?;
            dump(&connect(root, prefix)?, &script)
        }
        [mode, root, prefix, rest @ ..] if mode == "latency" => {
            latency(&connect(root, prefix)?, &LatencyArgs::parse(rest)?)
        }
        _ => {
            Err("usage: frame_dump dump ROOT PREFIX SCRIPT | latency ROOT PREFIX [options]".into())
        }
    }
}

fn connect(root: &str, prefix: &str) -> Result<Client<ipc::Service>, Box<dyn Error>> {
    Ok(ClientBuilder::new()
        .root(root)
        .iceoryx_prefix(prefix)
        .reply_timeout(Duration::from_secs(10))
        .connect::<ipc::Service>()?)
}

// ---------------------------------------------------------------------------------------
// dump

/// Runs `script` on a fresh scene and prints every result frame as a JSON line.
fn dump(client: &Client<ipc::Service>, script: &str) -> Result<(), Box<dyn Error>> {
    let scene = client.create_scene()?;
    let link = client.open_scene(scene)?;
    let mut lines = script
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .filter(|l| !l.is_empty());
    while let Some(line) = lines.next() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let (command, rest) = words.split_first().ok_or("empty line")?;
        match *command {
            "shape" => {
                client.register_primitive(scene, primitive(rest)?)?;
            }
            "convex" => {
                let n = int(rest.first())?;
                client.register_convex(scene, &points(&rest[1..], n)?)?;
            }
            "mesh" => {
                let (nv, nt) = (int(rest.first())?, int(rest.get(1))?);
                let vertices = points(&rest[2..2 + 3 * nv as usize], nv)?;
                let triangles = rest[2 + 3 * nv as usize..]
                    .chunks_exact(3)
                    .map(|t| Ok([int(t.first())?, int(t.get(1))?, int(t.get(2))?]))
                    .collect::<Result<Vec<_>, Box<dyn Error>>>()?;
                if triangles.len() != nt as usize {
                    return Err(
                        format!("mesh: {} triangles, expected {nt}", triangles.len()).into(),
                    );
                }
                client.register_mesh(scene, &vertices, &triangles)?;
            }
            "body" => {
                let [shape, motion_word, group, mask, margin_word, pose @ ..] = rest else {
                    return Err(format!("bad body line: {line}").into());
                };
                let (position, orientation) = pose_of(pose)?;
                client.add_body(
                    scene,
                    &BodySpec {
                        shape: int(Some(shape))?,
                        position,
                        orientation,
                        motion: motion(motion_word)?,
                        group: int(Some(group))?,
                        mask: int(Some(mask))?,
                        margin: margin(margin_word)?,
                    },
                )?;
            }
            "update" => {
                let [body, motion_word, group, mask, margin_word] = rest else {
                    return Err(format!("bad update line: {line}").into());
                };
                let (body, group, mask) = (int(Some(body))?, int(Some(group))?, int(Some(mask))?);
                let (motion, margin) = (motion(motion_word)?, margin(margin_word)?);
                client.update_body(scene, body, motion, group, mask, margin)?;
            }
            "remove" => client.remove_body(scene, int(rest.first())?)?,
            "broad" => {
                let code = BroadPhaseCode::from_u32(int(rest.first())?).ok_or("bad broad code")?;
                client.set_broad_phase(scene, code)?;
            }
            "frame" => {
                let [seq, budget, flags, n] = rest else {
                    return Err(format!("bad frame line: {line}").into());
                };
                let (seq, budget): (u64, u64) = (seq.parse()?, budget.parse()?);
                let poses = (0..int(Some(n))?)
                    .map(|_| pose_record(lines.next().ok_or("missing pose line")?))
                    .collect::<Result<Vec<_>, _>>()?;
                link.publish_poses(seq, budget, int(Some(flags))?, &poses)?;
                let frame = link
                    .receive_results_for(seq, FRAME_TIMEOUT)?
                    .ok_or_else(|| format!("no answer to frame {seq}"))?;
                println!("{}", frame_json(frame.header(), frame.records()));
            }
            other => return Err(format!("unknown command {other:?}").into()),
        }
    }
    client.drop_scene(scene)?;
    Ok(())
}

fn int(word: Option<&&str>) -> Result<u32, Box<dyn Error>> {
    Ok(word.ok_or("missing number")?.parse()?)
}

fn float(word: &str) -> Result<f64, Box<dyn Error>> {
    Ok(word.parse()?)
}

fn points(words: &[&str], n: u32) -> Result<Vec<[f64; 3]>, Box<dyn Error>> {
    if words.len() != 3 * n as usize {
        return Err(format!("{} coordinates for {n} points", words.len()).into());
    }
    words
        .chunks_exact(3)
        .map(|p| Ok([float(p[0])?, float(p[1])?, float(p[2])?]))
        .collect()
}

fn primitive(words: &[&str]) -> Result<Primitive, Box<dyn Error>> {
    let d: Vec<f64> = words[1..]
        .iter()
        .map(|w| float(w))
        .collect::<Result<_, _>>()?;
    Ok(match (words.first().copied(), d.as_slice()) {
        (Some("sphere"), &[radius]) => Primitive::Sphere { radius },
        (Some("capsule"), &[radius, half_height]) => Primitive::Capsule {
            radius,
            half_height,
        },
        (Some("cuboid"), &[x, y, z]) => Primitive::Cuboid {
            half_extents: [x, y, z],
        },
        (Some("cylinder"), &[radius, half_height]) => Primitive::Cylinder {
            radius,
            half_height,
        },
        (Some("cone"), &[radius, half_height]) => Primitive::Cone {
            radius,
            half_height,
        },
        _ => return Err(format!("bad shape: {words:?}").into()),
    })
}

fn motion(word: &str) -> Result<Motion, Box<dyn Error>> {
    Ok(match word {
        "static" => Motion::Static,
        "kinematic" => Motion::Kinematic,
        "dynamic" => Motion::Dynamic,
        _ => return Err(format!("bad motion {word:?}").into()),
    })
}

fn margin(word: &str) -> Result<Option<f64>, Box<dyn Error>> {
    Ok(if word == "default" {
        None
    } else {
        Some(float(word)?)
    })
}

fn pose_of(words: &[&str]) -> Result<([f64; 3], [f64; 4]), Box<dyn Error>> {
    let v: Vec<f64> = words.iter().map(|w| float(w)).collect::<Result<_, _>>()?;
    match v.as_slice() {
        &[x, y, z, qx, qy, qz, qw] => Ok(([x, y, z], [qx, qy, qz, qw])),
        _ => Err(format!("bad pose: {words:?}").into()),
    }
}

fn pose_record(line: &str) -> Result<PoseRecord, Box<dyn Error>> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let ["pose", body, pose @ ..] = words.as_slice() else {
        return Err(format!("expected a pose line: {line}").into());
    };
    let (position, orientation) = pose_of(pose)?;
    Ok(PoseRecord {
        body: int(Some(body))?,
        reserved: 0,
        position,
        orientation,
    })
}

/// A result frame as one JSON line; floats as the hex of their bits.
fn frame_json(h: &ResultFrameHeader, records: &[ResultRecord]) -> String {
    let mut out = format!(
        "{{\"frame_seq\":{},\"protocol_version\":{},\"status\":{},\"error_body\":{},\
         \"completeness\":{},\"deepest_level\":{},\"pair_count\":{},\"contact_count\":{},\
         \"candidate_count\":{},\"toi_count\":{},\"flags\":{},\"dropped_candidates\":{},\
         \"min_budget_ns\":{},\"records\":[",
        h.frame_seq,
        h.protocol_version,
        h.status,
        h.error_body,
        h.completeness,
        h.deepest_level,
        h.pair_count,
        h.contact_count,
        h.candidate_count,
        h.toi_count,
        h.flags,
        h.dropped_candidates,
        h.min_budget_ns
    );
    for (i, r) in records.iter().enumerate() {
        let bits = |x: f64| format!("\"{:016x}\"", x.to_bits());
        let vec = |v: [f64; 3]| format!("[{},{},{}]", bits(v[0]), bits(v[1]), bits(v[2]));
        let _ = write!(
            out,
            "{}{{\"kind\":{},\"body_a\":{},\"body_b\":{},\"index\":{},\"count\":{},\"flags\":{},\
             \"distance\":{},\"error_bound\":{},\"point_a\":{},\"point_b\":{},\"normal\":{},\
             \"time\":{}}}",
            if i == 0 { "" } else { "," },
            r.kind,
            r.body_a,
            r.body_b,
            r.index,
            r.count,
            r.flags,
            bits(r.distance),
            bits(r.error_bound),
            vec(r.point_a),
            vec(r.point_b),
            vec(r.normal),
            bits(r.time)
        );
    }
    out.push_str("]}");
    out
}

// ---------------------------------------------------------------------------------------
// latency: the scene of `proxima_ipc::tools::latency_scene` (as `examples/ipc_latency.rs`),
// measured from this client.

struct LatencyArgs {
    bodies: usize,
    frames: usize,
    warmup: usize,
    budget_ns: u64,
}

impl LatencyArgs {
    fn parse(words: &[String]) -> Result<Self, Box<dyn Error>> {
        let mut args = Self {
            bodies: 100,
            frames: 5000,
            warmup: 500,
            budget_ns: 1_000_000,
        };
        for pair in words.chunks(2) {
            let [flag, value] = pair else {
                return Err(format!("{pair:?}: a flag needs a value").into());
            };
            match flag.as_str() {
                "--bodies" => args.bodies = value.parse()?,
                "--frames" => args.frames = value.parse()?,
                "--warmup" => args.warmup = value.parse()?,
                "--budget-ns" => args.budget_ns = value.parse()?,
                _ => return Err(format!("unknown flag {flag}").into()),
            }
        }
        Ok(args)
    }
}

fn latency(client: &Client<ipc::Service>, args: &LatencyArgs) -> Result<(), Box<dyn Error>> {
    let scene = client.create_scene()?;
    let link = latency_scene::add_bodies(client, scene, args.bodies)?;
    let mut round_trips = LatencyRecorder::with_capacity(args.frames);
    let mut engine = LatencyRecorder::with_capacity(args.frames);
    for seq in 1..=(args.warmup + args.frames) as u64 {
        let t = seq as f64 * 1e-3;
        let started = Instant::now();
        link.publish_poses_with(seq, args.budget_ns, query::CLOSE, args.bodies, |i| {
            latency_scene::pose(i, args.bodies, t)
        })?;
        let frame = link
            .receive_results_for(seq, FRAME_TIMEOUT)?
            .ok_or_else(|| format!("no answer to frame {seq}"))?;
        let rtt = started.elapsed();
        if seq > args.warmup as u64 {
            round_trips.record(rtt);
            engine.record_ns(frame.header().elapsed_ns);
        }
    }
    client.drop_scene(scene)?;
    let (Some(rtt), Some(daemon)) = (round_trips.summary(), engine.summary()) else {
        return Err("no frames measured".into());
    };
    println!(
        "{{\"client\":\"rust\",\"bodies\":{},\"frames\":{},\"rtt_p50_ns\":{},\"rtt_p99_ns\":{},\
         \"rtt_mean_ns\":{},\"daemon_p50_ns\":{}}}",
        args.bodies, rtt.count, rtt.p50_ns, rtt.p99_ns, rtt.mean_ns, daemon.p50_ns
    );
    Ok(())
}
