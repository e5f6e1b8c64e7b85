use super::*;
use crate::geom::{Aabb, P3};
use crate::grouping::{Merge, Part, PartKind};
use foxglove::Encode;

fn encode<T: Encode>(m: &T) -> Vec<u8> {
    let mut buf = Vec::new();
    m.encode(&mut buf).expect("encode");
    buf
}

#[test]
fn merge_round_trips_with_distinct_values() {
    // Every field gets a different value, so swapping two fields would be caught.
    let m = Merge {
        step: 7,
        round: 3,
        a: 11,
        b: 13,
        new: 17,
        aabb: Aabb {
            min: P3::new(-1.5, -2.5, -3.5),
            max: P3::new(4.25, 5.25, 6.25),
        },
        diameter: 9.125,
        fill: 0.75,
        balance: 1.0625,
        cost: 6.5,
        queue_len: 1 << 20,
        active: true,
    };
    let bytes = encode(&MergeEvent::from(&m));
    let decoded = MergeEvent::decode(&bytes).unwrap().to_merge().unwrap();
    assert_eq!(decoded, (m, Some(m.aabb)));
    // Without its box the message is 54 bytes shorter and reads back without it; a box with
    // only some corners is refused.
    let short = encode(&MergeEvent::from(&m).without_box());
    assert_eq!(short.len() + 6 * 9, bytes.len());
    let (read, aabb) = MergeEvent::decode(&short).unwrap().to_merge().unwrap();
    assert_eq!(
        (read, aabb),
        (
            Merge {
                aabb: Aabb::EMPTY,
                ..m
            },
            None
        )
    );
    let partial = MergeEvent {
        max_z: None,
        ..MergeEvent::from(&m)
    };
    assert!(partial.to_merge().is_err());
    let r = RoundEvent {
        doubling: true,
        round: 2,
        dlimit: 0.5,
        glimit: 0.125,
        active: 5,
        dormant: 6,
        pairs: u64::MAX,
        merges: 9,
    };
    assert_eq!(RoundEvent::decode(&encode(&r)).unwrap(), r);
    let f = FinishEvent {
        root: 4,
        rounds: 2,
        merges: 2,
    };
    assert_eq!(FinishEvent::decode(&encode(&f)).unwrap(), f);
    for kind in [
        PartKind::Chunk { level: 3, keep: 5 },
        PartKind::Component { index: 6 },
        PartKind::Copy {
            of: 2,
            rotation: [0.5, -1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0],
            translation: [9.0, 10.0, -11.0],
        },
        PartKind::Top,
        PartKind::Twins,
    ] {
        let p = Part {
            id: 4,
            kind,
            bodies: 19,
            first_step: 1 << 30,
        };
        let back = PartEvent::decode(&encode(&PartEvent::from(&p))).unwrap();
        assert_eq!(Part::try_from(&back).unwrap(), p);
    }
    let bad = PartEvent {
        kind: 9,
        ..PartEvent::default()
    };
    assert!(Part::try_from(&bad).is_err());
}

#[test]
fn only_copies_carry_a_transform() {
    let part = |kind| Part {
        id: 70_000,
        kind,
        bodies: 7,
        first_step: 900_000,
    };
    let chunk = encode(&PartEvent::from(&part(PartKind::Chunk {
        level: 12,
        keep: 3,
    })));
    // Seven small varints, not twelve doubles of zeros besides.
    assert!(chunk.len() <= 7 * 4, "{} bytes", chunk.len());
    let decoded = PartEvent::decode(&chunk).unwrap();
    assert_eq!((decoded.r0, decoded.tz), (None, None));
    let copy = PartEvent::from(&part(PartKind::Copy {
        of: 1,
        rotation: [0.0; 9],
        translation: [0.0; 3],
    }));
    // A copy's transform is written even when it is zero, and required when read.
    let back = PartEvent::decode(&encode(&copy)).unwrap();
    assert_eq!(back.r4, Some(0.0));
    let torn = PartEvent { ty: None, ..back };
    assert!(Part::try_from(&torn).unwrap_err().contains("translation"));
}

#[test]
fn schema_is_protobuf() {
    let schema = MergeEvent::get_schema().unwrap();
    assert_eq!(schema.name, "mergeevent.MergeEvent");
    assert_eq!(schema.encoding, "protobuf");
    assert_eq!(MergeEvent::get_message_encoding(), "protobuf");
}

#[test]
fn bad_bytes_are_errors() {
    let bytes = encode(&MergeEvent::default());
    assert!(MergeEvent::decode(&bytes[..bytes.len() - 3]).is_err());
    assert!(MergeEvent::decode(&[]).unwrap_err().contains("missing"));
    assert!(MergeEvent::decode(&[0xff; 12]).is_err());
    // A foreign message with the right field numbers but wrong wire types.
    assert!(DormantEvent::decode(&encode(&FinishEvent::default())).is_err());
}
