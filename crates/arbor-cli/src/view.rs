//! `arbor view SCENE`: the live debugging display in a web page ([`arbor_view`]). Reads the scene as
//! `render` does (its warnings, its limits), starts the server, prints the address to open (with its
//! token) and serves until SIGINT or SIGTERM.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;

use arbor::accel::AccelKind;
use clap::Args;

use crate::Failure;

/// Arguments of `arbor view`.
#[derive(Args)]
pub struct ViewArgs {
    /// Scene file (.xml or .json). Without one, shows the built-in example Cornell box.
    pub scene: Option<PathBuf>,
    /// Port to listen on (0: any free port, printed).
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// Address to listen on. Anything but loopback lets other machines reach the page (the token is
    /// still required).
    #[arg(long, value_name = "ADDR", default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    pub listen: IpAddr,
    /// Acceleration structure to start with (the page switches among all of them).
    #[arg(long, default_value = "bvh-sah", value_parser = crate::render::parse_accel)]
    pub accel: AccelKind,
    /// A build parameter of the structure, KEY=VALUE (repeatable).
    #[arg(long = "accel-param", value_name = "KEY=VALUE")]
    pub accel_params: Vec<String>,
    #[command(flatten)]
    pub threads: crate::threads::ThreadsArg,
    /// Lift the limits on image size, samples and recursion depth.
    #[arg(long)]
    pub no_limits: bool,
    /// No warnings about the scene.
    #[arg(long)]
    pub no_warnings: bool,
}

/// Runs `arbor view` until a signal stops it.
pub fn run(args: ViewArgs) -> Result<(), Failure> {
    args.threads.apply()?;
    let accel = crate::render::accel_spec(args.accel, &args.accel_params)?;
    let desc = crate::render::read_scene(&args.scene)?;
    arbor::scene::check_limits(&desc, None, &crate::render::limits(args.no_limits))?;
    if desc.cameras.is_empty() {
        return Err(arbor::Error::Invalid(format!("{}: the scene has no camera", crate::shown(&args.scene))).into());
    }
    if !args.no_warnings {
        for w in crate::warnings::scene_warnings(&desc) {
            eprintln!("warning: {w}");
        }
    }
    let config = arbor_view::ViewConfig { desc, accel, addr: SocketAddr::new(args.listen, args.port), token: None };
    let server = arbor_view::Server::start(config)?;
    say!("arbor view of {}: open {}", crate::shown(&args.scene), server.url());
    say!("(Ctrl-C stops it)");
    loop {
        std::thread::park();
    }
}
