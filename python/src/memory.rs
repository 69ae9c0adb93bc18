//! What a render held in memory may take, checked before it is taken. A call returns its samples
//! (and its tables) whole, and a long scene makes them larger than a machine: a day at 48 kHz is
//! 16.6 GB of samples. An allocation that fails aborts the process, interpreter and all, so every
//! one that grows with the scene is checked first, against the memory the system has available
//! and against what this process may allocate (its address-space limit), and refused with the
//! figure.

use sake_glug_render::human_bytes;

/// Bytes of one sample as a render returns it (f32).
const SAMPLE_BYTES: u64 = std::mem::size_of::<f32>() as u64;

/// The fewest samples a buffer grows by: a few blocks, so that short renders do not regrow often.
const MIN_GROWTH_SAMPLES: usize = 1 << 16;

/// Memory the system can give without swapping (Linux: `MemAvailable` of `/proc/meminfo`, as the
/// command line reads it in crates/render/src/memory.rs, where that reader is private to the
/// crate); `None` where it cannot be told, and only the allocation itself is checked then.
fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo
        .lines()
        .find_map(|line| line.strip_prefix("MemAvailable:"))?;
    let kilobytes: u64 = line.trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kilobytes.saturating_mul(1024))
}

/// Why `bytes` more cannot be held: more than the system has available ("more than the 3.1 GB
/// available"), or `None`.
fn beyond_available(bytes: u64) -> Option<String> {
    let available = available_bytes().filter(|&available| bytes > available)?;
    Some(format!(
        "more than the {} available",
        human_bytes(available)
    ))
}

/// Why an allocation failed: the address-space limit (`ulimit -v`), or past what the system
/// could ever give.
const BEYOND_LIMIT: &str = "more than this process may allocate (its memory limit)";

/// Why `bytes` more cannot be held, checked against the memory available and against what this
/// process may allocate, or `None` if they can: for allocations out of this crate's reach (the
/// render crate's tables), whose failure would abort.
fn refusal(bytes: u64) -> Option<String> {
    beyond_available(bytes).or_else(|| {
        // Taken and given back untouched: it costs address space, not memory, and fails as the
        // real allocations would.
        let mut probe = Vec::<u8>::new();
        let fits = usize::try_from(bytes)
            .ok()
            .is_some_and(|bytes| probe.try_reserve_exact(bytes).is_ok());
        (!fits).then(|| BEYOND_LIMIT.to_owned())
    })
}

/// Where a render gets to in seconds, for a message.
fn seconds(samples: u64, sample_rate: u32) -> String {
    format!(
        "{:.1} s at {sample_rate} Hz",
        samples as f64 / sample_rate as f64
    )
}

/// The samples of a render, in memory that was checked before it was taken.
pub struct Samples {
    samples: Vec<f32>,
    sample_rate: u32,
}

impl Samples {
    /// Room for exactly `count` samples (a render whose length is known), or why there is none.
    pub fn with_room(count: u64, sample_rate: u32) -> Result<Self, String> {
        let bytes = count.saturating_mul(SAMPLE_BYTES);
        let refused = |why: String| {
            format!(
                "the render's {count} samples ({}) need {} of memory, {why}; `sake-glug render` \
                 writes a render of any length to a file",
                seconds(count, sample_rate),
                human_bytes(bytes)
            )
        };
        if let Some(why) = beyond_available(bytes) {
            return Err(refused(why));
        }
        let mut samples = Vec::new();
        usize::try_from(count)
            .ok()
            .and_then(|count| samples.try_reserve_exact(count).ok())
            .ok_or_else(|| refused(BEYOND_LIMIT.into()))?;
        Ok(Self {
            samples,
            sample_rate,
        })
    }

    /// An empty buffer for a render whose length is not known before it ends: it grows as the
    /// render does, each time only if the memory for it is there.
    pub fn growing(sample_rate: u32) -> Self {
        Self {
            samples: Vec::new(),
            sample_rate,
        }
    }

    /// Appends `block`, refused (with the figure) if the buffer would have to grow beyond what
    /// can be held.
    pub fn push(&mut self, block: &[f32]) -> Result<(), String> {
        let (len, capacity) = (self.samples.len(), self.samples.capacity());
        if capacity - len < block.len() {
            // Doubling: amortised, and the excess is given back when the render ends.
            let wanted = (capacity * 2)
                .max(len + block.len())
                .max(MIN_GROWTH_SAMPLES);
            let more = (wanted - capacity) as u64 * SAMPLE_BYTES;
            let refused = |why: String| {
                format!(
                    "the render reached {len} samples ({}) and needs {} more memory to go on, \
                     {why}; give the scene a duration_s that fits, or let `sake-glug render` \
                     write it to a file",
                    seconds(len as u64, self.sample_rate),
                    human_bytes(more)
                )
            };
            if let Some(why) = beyond_available(more) {
                return Err(refused(why));
            }
            self.samples
                .try_reserve_exact(wanted - len)
                .map_err(|_| refused(BEYOND_LIMIT.into()))?;
        }
        self.samples.extend_from_slice(block);
        Ok(())
    }

    /// The samples, holding no more memory than they take.
    pub fn into_vec(mut self) -> Vec<f32> {
        self.samples.shrink_to_fit();
        self.samples
    }
}

/// What the tables of a render are made of, counted by a first pass that kept nothing.
pub struct TableSizes {
    pub samples: u64,
    /// `None` before they are counted: the check is then of the least the tables can take.
    pub units: Option<u64>,
    pub state_rows: u64,
}

impl TableSizes {
    /// Refuses tables that cannot be held, with the figure. `render_tables_until` collects them
    /// in vectors that grow by doubling (up to twice their length at once), then the columns are
    /// copied into NumPy arrays while the rows still exist: the peak of both is checked.
    pub fn check(
        &self,
        unit_row_bytes: u64,
        state_row_bytes: u64,
        columns: [u64; 2],
    ) -> Result<(), String> {
        let column_bytes = std::mem::size_of::<f64>() as u64;
        let units = self.units.unwrap_or(0);
        let rows = self
            .samples
            .saturating_mul(SAMPLE_BYTES)
            .saturating_add(units.saturating_mul(unit_row_bytes))
            .saturating_add(self.state_rows.saturating_mul(state_row_bytes));
        let arrays = units
            .saturating_mul(columns[0] * column_bytes)
            .saturating_add(self.state_rows.saturating_mul(columns[1] * column_bytes));
        let bytes = rows.saturating_mul(2).saturating_add(arrays);
        let Some(why) = refusal(bytes) else {
            return Ok(());
        };
        let (units, need) = match self.units {
            Some(units) => (format!("{units} units"), "up to"),
            None => ("its units not yet counted".to_owned(), "at least"),
        };
        Err(format!(
            "the render's tables ({} samples, {} state rows, {units}) need {need} {} of memory, \
             {why}; `sake-glug render --units --state` writes them to files of any length",
            self.samples,
            self.state_rows,
            human_bytes(bytes)
        ))
    }
}
