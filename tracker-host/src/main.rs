fn main() -> std::process::ExitCode {
    tracker_host::cli::main()
}
