//! A global allocator that counts, per thread, every allocation, reallocation and free, so a test
//! can see that a stretch of code made none (other test threads count on their own).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    // const-initialised and without a destructor: reading it never allocates.
    static CALLS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    // During thread teardown the slot may be gone: such a call is not the code under test.
    let _ = CALLS.try_with(|calls| calls.set(calls.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, pointer: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(pointer, layout, new_size) }
    }

    unsafe fn dealloc(&self, pointer: *mut u8, layout: Layout) {
        count();
        unsafe { System.dealloc(pointer, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `body` and returns what it gave and the allocator calls this thread made meanwhile.
pub fn counted<T>(body: impl FnOnce() -> T) -> (T, u64) {
    let before = CALLS.with(Cell::get);
    let value = body();
    (value, CALLS.with(Cell::get) - before)
}

#[test]
fn the_counter_sees_an_allocation() {
    let (_, calls) = counted(|| drop(std::hint::black_box(vec![1u8; 10])));
    assert_eq!(calls, 2, "an allocation and its free");
}
