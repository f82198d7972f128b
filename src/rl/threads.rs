//! The thread count candle uses, fixed once per process.
//!
//! candle 0.11 asks for its thread count on every matrix product. Unless `RAYON_NUM_THREADS`
//! is set, on Linux machines that do not publish CPU capacities (most x86 machines) it answers
//! by parsing `/proc/cpuinfo` (`num_cpus::get_physical`) each time: about a third of the time
//! of a designer's Solver run went there and to the scheduler. Setting the variable once, to
//! the count rayon would use anyway, makes the answer an environment lookup.

/// Sets `RAYON_NUM_THREADS` to the machine's available parallelism unless the user set it.
///
/// # Safety
/// Changes the process environment: call it first thing in `main`, before any other thread
/// exists (see [`std::env::set_var`]).
pub unsafe fn fix_thread_count() {
    if std::env::var_os("RAYON_NUM_THREADS").is_none() {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        // SAFETY: the caller guarantees that no other thread reads or writes the environment.
        unsafe { std::env::set_var("RAYON_NUM_THREADS", threads.to_string()) };
    }
}
