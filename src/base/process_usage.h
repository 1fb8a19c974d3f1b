#pragma once
/// What the process has used: CPU time (all threads) and resident memory (Linux),
/// for the build timings and `sahara bench`'s memory figures.

namespace sahara {

/// CPU time of the whole process (every thread) so far, in milliseconds.
double process_cpu_ms();

/// Resident set high-water mark in MiB: since the start, or since reset_peak_rss.
double peak_rss_mib();

/// Starts a new high-water mark at the current resident size, so the next
/// peak_rss_mib is the peak of what runs in between (Linux's /proc/self/clear_refs;
/// where that cannot be written the mark just keeps counting from the start).
void reset_peak_rss();

/// Resident set size now, in MiB (/proc/self/statm); 0 where that file does not exist.
double current_rss_mib();

}  // namespace sahara
