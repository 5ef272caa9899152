//! Per-light slots ([`gpu::Slots`]): one a light recorded in a submission, the same ones again
//! after each submission, a typed refusal (or, with `next_or_own`, a slot of the light's own)
//! past the most a submission may hold.

use gpu::{Gpu, GpuError, MAX_SLOTS_PER_SUBMISSION, Slots};

fn take(gpu: &Gpu, slots: &Slots<u32>, made: &mut u32) -> Result<u32, GpuError> {
    slots.next(
        gpu,
        || {
            *made += 1;
            *made
        },
        |slot| *slot,
    )
}

#[test]
fn slots_are_handed_out_in_order_and_start_over_at_each_submission() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let slots = Slots::new();
    let mut made = 0;
    let first: Vec<u32> = (0..3).map(|_| take(&gpu, &slots, &mut made).unwrap()).collect();
    assert_eq!(first, [1, 2, 3]);
    // a submission through the Gpu, then one the caller marks: the same slots again
    gpu.submit(gpu.encoder("empty"));
    let second: Vec<u32> = (0..4).map(|_| take(&gpu, &slots, &mut made).unwrap()).collect();
    assert_eq!(second, [1, 2, 3, 4], "only the fourth slot is new");
    gpu.mark_submitted();
    assert_eq!(take(&gpu, &slots, &mut made).unwrap(), 1);
    assert_eq!(slots.made(), 4);
}

#[test]
fn a_submission_holds_at_most_the_slot_limit_and_then_lights_get_their_own() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let slots = Slots::new();
    let mut made = 0;
    for _ in 0..MAX_SLOTS_PER_SUBMISSION {
        take(&gpu, &slots, &mut made).unwrap();
    }
    let refused = take(&gpu, &slots, &mut made);
    assert!(matches!(refused, Err(GpuError::TooLarge { .. })), "{refused:?}");
    assert!(refused.unwrap_err().to_string().contains("mark_submitted"));
    // the infallible form gives the light a slot of its own, made for it and not kept
    let own = slots.next_or_own(&gpu, || 7u32, |slot| *slot);
    assert_eq!(own, 7);
    assert_eq!(slots.made(), MAX_SLOTS_PER_SUBMISSION);
    gpu.mark_submitted();
    assert_eq!(take(&gpu, &slots, &mut made).unwrap(), 1);
}
