fn main() -> std::process::ExitCode {
    glint::cli::main()
}
