fn main() -> std::process::ExitCode {
    rotorsim::cli::main()
}
