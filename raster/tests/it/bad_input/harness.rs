//! The sandbox every bad-input test runs the `lucent` binary in.
//!
//! A [`Sandbox`] is a fresh directory holding a small valid scene (`scene.toml`, 32 × 32
//! pixels, 500 samples, writing `out.png` and `out.exr`) and both output files pre-filled with
//! known bytes. [`Sandbox::fails`] runs the binary there and asserts the three promises made
//! for bad input at once: the expected exit code, a message on stderr naming the problem, and the
//! directory byte-for-byte as it was (no output written or overwritten, no temporary file
//! left behind).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicU64, Ordering};

/// What the pre-filled outputs hold before every run.
pub const PREVIOUS: &[u8] = b"previous contents: must survive a failed run\n";

/// Files larger than this are compared by length and time of modification in a
/// [`Sandbox::snapshot`] (a mesh of more than 1 GiB, say).
const LARGE_FILE: u64 = 64 << 20;

/// The exit code of a Rust panic: never acceptable.
const PANIC_EXIT: i32 = 101;

/// A valid scene using every kind of number the format has (camera, shapes, all light
/// types, every render setting), so that [`super::scene`] can replace each in turn.
/// `OBJECT` and `MATERIAL` are placeholders for per-test variants.
pub const TEMPLATE: &str = r#"# bad-input test scene: 32 × 32 pixels, 500 samples
[camera]
position = [0.0, -5.0, 1.2]
target = [0.0, 0.0, 0.5]
up = [0.0, 0.0, 1.0]
fov = 35.0
width = 32
height = 32

[[object]]
name = "ball"
OBJECT
translate = [0.0, 0.0, 0.5]
rotate = [0.0, 0.0, 15.0]
scale = 1.0
material = "m"

[[object]]
name = "plate"
shape = "box"
size = [1.0, 1.0, 0.05]
translate = [-0.6, 0.0, 1.6]
material = "grey"

[material.m]
type = "translucent"
MATERIAL
eta = 1.3
specular = { exponent = 60.0, strength = 0.4 }

[material.grey]
type = "lambert"
albedo = [0.2, 0.2, 0.2]

[[light]]
type = "point"
position = [0.0, -3.0, 5.0]
color = [1.0, 0.97, 0.92]
intensity = 25.0

[[light]]
type = "spot"
position = [2.0, -2.0, 3.0]
direction = [-1.0, 1.0, -1.0]
inner_angle = 10.0
outer_angle = 20.0
intensity = 5.0

[[light]]
type = "directional"
direction = [0.0, 0.3, -1.0]
irradiance = 0.2

[[light]]
type = "sphere"
center = [-2.0, -2.0, 3.0]
radius = 0.3
intensity = 4.0
samples = 4

[render]
method = "edge-aware"
samples = 500
epsilon = 0.05
smoothing = 1.5
ell_min = 0.0001
cull_tolerance = 0.0001
aa = 2
exposure = 0.0
threads = 1
seed = 7

[output]
png = "out.png"
exr = "out.exr"
layers = ["exitance"]
"#;

/// The default object: a built-in sphere (it has UVs, for textured materials).
pub const SPHERE: &str = "shape = \"sphere\"\nradius = 0.5\nsegments = 24";

/// The default material: constant K_d and mean free path.
pub const CONSTANT: &str = "kd = [0.8, 0.6, 0.4]\nmean_free_path = 0.05";

/// The template with `object` and `material` filled in.
pub fn scene(object: &str, material: &str) -> String {
    TEMPLATE
        .replace("OBJECT", object)
        .replace("MATERIAL", material)
}

/// A fresh directory with `scene.toml` and pre-filled `out.png` and `out.exr`; removed on
/// drop.
pub struct Sandbox {
    dir: PathBuf,
    env: Vec<(&'static str, &'static str)>,
    /// The binary's address-space limit in KiB (`ulimit -v`), if any.
    address_space: Option<u64>,
}

impl Sandbox {
    /// A sandbox with the default scene.
    pub fn new(tag: &str) -> Sandbox {
        Sandbox::with_scene(tag, &scene(SPHERE, CONSTANT))
    }

    /// A sandbox whose `scene.toml` is `text`.
    pub fn with_scene(tag: &str, text: &str) -> Sandbox {
        static N: AtomicU64 = AtomicU64::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("lucent-bad-input-{tag}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create the sandbox");
        let sandbox = Sandbox {
            dir,
            env: Vec::new(),
            address_space: None,
        };
        sandbox.write("scene.toml", text.as_bytes());
        sandbox.reset_outputs();
        sandbox
    }

    /// The sandbox, running the binary with the environment variable `key` set to `value`.
    pub fn with_env(mut self, key: &'static str, value: &'static str) -> Sandbox {
        self.env.push((key, value));
        self
    }

    /// The sandbox, running the binary with at most `kib` KiB of address space (`ulimit -v`
    /// through `sh`), so that large allocations fail as they would on a smaller machine.
    pub fn with_address_space(mut self, kib: u64) -> Sandbox {
        self.address_space = Some(kib);
        self
    }

    /// A path inside the sandbox.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes a file into the sandbox.
    pub fn write(&self, name: &str, bytes: &[u8]) {
        std::fs::write(self.path(name), bytes).expect("write a sandbox file");
    }

    /// Writes `head` into the sandbox as `name` and lengthens the file to `len` bytes: the rest
    /// reads as zeros without being written (a sparse file: no disk space, no time), so that
    /// tests can hand the binary files of a gibibyte and more.
    pub fn write_sparse(&self, name: &str, head: &[u8], len: u64) {
        self.write(name, head);
        std::fs::File::options()
            .write(true)
            .open(self.path(name))
            .and_then(|f| f.set_len(len))
            .expect("lengthen a sandbox file");
    }

    /// Reads a file of the sandbox.
    pub fn read(&self, name: &str) -> Vec<u8> {
        std::fs::read(self.path(name)).expect("read a sandbox file")
    }

    /// Puts [`PREVIOUS`] back into `out.png` and `out.exr`.
    pub fn reset_outputs(&self) {
        self.write("out.png", PREVIOUS);
        self.write("out.exr", PREVIOUS);
    }

    /// Every entry of the directory (recursively) with its contents (`None` for directories;
    /// for a file of more than [`LARGE_FILE`] bytes, its length and time of modification).
    pub fn snapshot(&self) -> BTreeMap<String, Option<Vec<u8>>> {
        fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Option<Vec<u8>>>) {
            for entry in std::fs::read_dir(dir).expect("list the sandbox") {
                let path = entry.expect("sandbox entry").path();
                let name = path
                    .strip_prefix(root)
                    .expect("inside the sandbox")
                    .display()
                    .to_string();
                if path.is_dir() {
                    out.insert(name, None);
                    walk(root, &path, out);
                } else {
                    let meta = path.metadata().expect("a sandbox file's metadata");
                    let len = meta.len();
                    let contents = if len > LARGE_FILE {
                        // Its length and time of modification: reading it twice per run cost
                        // seconds, and a run that rewrote it would change the time.
                        let modified = meta.modified();
                        format!("{len} bytes, modified {modified:?}").into_bytes()
                    } else {
                        std::fs::read(&path).expect("read a sandbox file")
                    };
                    out.insert(name, Some(contents));
                }
            }
        }
        let mut out = BTreeMap::new();
        walk(&self.dir, &self.dir, &mut out);
        out
    }

    /// Runs `lucent args…` in the sandbox.
    pub fn run(&self, args: &[&str]) -> Output {
        let binary = env!("CARGO_BIN_EXE_lucent");
        let mut command = match self.address_space {
            None => Command::new(binary),
            Some(kib) => {
                let mut sh = Command::new("sh");
                sh.args([
                    "-c",
                    &format!("ulimit -v {kib} && exec \"$0\" \"$@\""),
                    binary,
                ]);
                sh
            }
        };
        command
            .args(args)
            .current_dir(&self.dir)
            .env_remove("RAYON_NUM_THREADS")
            .envs(self.env.iter().copied())
            .output()
            .expect("start the lucent binary")
    }

    /// Runs `lucent args…` and asserts that it fails cleanly: exit code `code`, nothing on
    /// stdout, an `error:` message on stderr containing every one of `needles`, no panic, and
    /// the sandbox exactly as it was. Returns the message.
    pub fn fails(&self, args: &[&str], code: i32, needles: &[&str]) -> String {
        let before = self.snapshot();
        let out = self.run(args);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let ctx = format!(
            "lucent {}\nstderr: {stderr}\nstdout: {stdout}",
            args.join(" ")
        );
        assert_eq!(out.status.code(), Some(code), "exit code of {ctx}");
        assert!(starts_with_error(&stderr), "no error message: {ctx}");
        assert!(!stderr.contains("panicked"), "panic: {ctx}");
        assert!(stdout.is_empty(), "output on stdout: {ctx}");
        for needle in needles {
            assert!(stderr.contains(needle), "message lacks `{needle}`: {ctx}");
        }
        self.assert_unchanged(&before, &ctx);
        stderr
    }

    /// Runs `lucent args…` on input that may or may not be valid (a truncation sweep, say):
    /// it must either succeed, or fail as [`Sandbox::fails`] requires with exit 1 and a message
    /// naming `needle`. Returns whether it failed. After a success the outputs are reset.
    pub fn succeeds_or_fails(&self, args: &[&str], needle: &str) -> bool {
        let before = self.snapshot();
        let out = self.run(args);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        let ctx = format!("lucent {}\nstderr: {stderr}", args.join(" "));
        assert_ne!(out.status.code(), Some(PANIC_EXIT), "panic: {ctx}");
        assert!(!stderr.contains("panicked"), "panic: {ctx}");
        match out.status.code() {
            Some(0) => {
                self.reset_outputs();
                false
            }
            Some(1) => {
                assert!(starts_with_error(&stderr), "no error message: {ctx}");
                assert!(stderr.contains(needle), "message lacks `{needle}`: {ctx}");
                self.assert_unchanged(&before, &ctx);
                true
            }
            other => panic!("exit {other:?}: {ctx}"),
        }
    }

    /// Runs `lucent args…` and asserts success.
    pub fn succeeds(&self, args: &[&str]) -> Output {
        let out = self.run(args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "lucent {}\nstderr: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
        out
    }

    fn assert_unchanged(&self, before: &BTreeMap<String, Option<Vec<u8>>>, ctx: &str) {
        let after = self.snapshot();
        if &after != before {
            let changed: Vec<&String> = before
                .keys()
                .chain(after.keys())
                .filter(|k| before.get(*k) != after.get(*k))
                .collect();
            panic!("the run changed {changed:?} in the sandbox: {ctx}");
        }
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// True if `stderr` is an `error:` message, after at most one `warning:` line (the
/// under-resolution warning comes as soon as the sample count is known, before later errors).
fn starts_with_error(stderr: &str) -> bool {
    let rest = match stderr.strip_prefix("warning: ") {
        Some(w) => w.split_once('\n').map_or("", |(_, rest)| rest),
        None => stderr,
    };
    rest.starts_with("error: ")
}

/// The arguments of a quiet render of `scene.toml` plus `extra`.
pub fn render<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["scene.toml", "-q"];
    args.extend_from_slice(extra);
    args
}

/// CRC-32 (IEEE, as PNG chunks use it), bitwise.
pub fn crc32(data: &[u8]) -> u32 {
    let mut crc = 0xffff_ffff_u32;
    for &b in data {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG chunk with its length and CRC.
pub fn png_chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut crc_input = kind.to_vec();
    crc_input.extend_from_slice(data);
    out.extend_from_slice(&crc32(&crc_input).to_be_bytes());
    out
}

/// A PNG that is only a signature, an IHDR claiming `width × height` 8-bit RGB, and IEND:
/// what a decoder sees first, for the size checks.
pub fn png_header_only(width: u32, height: u32) -> Vec<u8> {
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    out.extend(png_chunk(b"IHDR", &ihdr));
    out.extend(png_chunk(b"IEND", &[]));
    out
}

/// A valid 8-bit RGB PNG of `width × height` mid-grey texels, encoded by lucent's own writer.
pub fn valid_png(sandbox: &Sandbox, name: &str, width: u32, height: u32) -> Vec<u8> {
    let rgb: Vec<u8> = (0..width * height)
        .flat_map(|i| [100 + (i % 50) as u8, 128, 160])
        .collect();
    lucent_raster::output::png::write_png_rgb8(&sandbox.path(name), width, height, &rgb)
        .expect("write a valid PNG");
    sandbox.read(name)
}

/// An OpenEXR of one `side × side` part whose channels `R`, `G`, `B` each hold `samples`,
/// written by the `exr` crate with `encoding`.
pub fn rgb_exr(
    side: usize,
    samples: exr::prelude::FlatSamples,
    encoding: exr::prelude::Encoding,
) -> Vec<u8> {
    use exr::prelude::*;
    let channels = ["R", "G", "B"].map(|name| AnyChannel::new(name, samples.clone()));
    let layer = Layer::new(
        Vec2(side, side),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(SmallVec::from_vec(channels.to_vec())),
    );
    let mut bytes = Vec::new();
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(std::io::Cursor::new(&mut bytes))
        .expect("EXR writes");
    bytes
}
