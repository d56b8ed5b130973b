"""Recorded bags: read back by rosbags, replayed through the planner, bad bags refused."""

from pathlib import Path

from conftest import REPO
from mcap.writer import Writer
import numpy as np
import pytest

from subapf_planner.bag.reader import BagError, read, topics
from subapf_planner.tools.replay import main as replay_main

DATA = REPO / 'test' / 'data'
BAGS = sorted(DATA.glob('*.mcap'))


def test_bags_are_small_and_present():
    assert len(BAGS) >= 2
    assert all(b.stat().st_size < 400_000 for b in BAGS)


@pytest.mark.parametrize('bag', BAGS, ids=lambda p: p.stem)
def test_rosbags_reads_the_same_messages(bag):
    from rosbags.highlevel import AnyReader
    ours = {}
    for m in read(bag):
        ours.setdefault(m.topic, []).append(m)
    with AnyReader([bag]) as reader:
        theirs = {}
        for conn, t, raw in reader.messages():
            theirs.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype)))
    assert set(ours) == set(theirs)
    for topic in ours:
        assert len(ours[topic]) == len(theirs[topic]), topic
    for mine, (t, other) in zip(ours['/scan'], theirs['/scan'], strict=True):
        assert mine.log_time_ns == t
        np.testing.assert_array_equal(np.asarray(mine.message.ranges, np.float32),
                                      other.ranges)
        assert mine.message.header.stamp.sec == other.header.stamp.sec
    for mine, (_, other) in zip(ours['/cmd_vel'], theirs['/cmd_vel'], strict=True):
        assert mine.message.twist.angular.z == other.twist.angular.z


@pytest.mark.parametrize('bag', BAGS, ids=lambda p: p.stem)
def test_replay_reproduces_recorded_commands(bag, capsys, tmp_path):
    out = tmp_path / 'replayed.mcap'
    assert replay_main([str(bag), '--tolerance', '1e-9', '-o', str(out)]) == 0
    text = capsys.readouterr().out
    assert 'first divergence: none' in text
    n = int(text.split('commands compared: ')[1].split()[0])
    assert n > 50
    assert topics(out) == {'/cmd_vel': 'geometry_msgs/msg/TwistStamped'}
    assert sum(1 for _ in read(out)) == n


def test_changed_parameter_makes_replay_differ_and_says_where(capsys):
    bag = DATA / 'fig6d_big_wall.mcap'
    assert replay_main([str(bag), '--method', 'subharmonic']) == 1
    text = capsys.readouterr().out
    assert 'first divergence: t = ' in text
    t = float(text.split('first divergence: t = ')[1].split()[0])
    assert 0.0 < t < 35.0


def test_truncated_bag_gives_clear_error(tmp_path, capsys):
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(BAGS[0].read_bytes()[:50_000])
    assert replay_main([str(cut)]) == 2
    err = capsys.readouterr().err
    assert 'cut.mcap' in err and ('truncated' in err or 'not a readable' in err)
    assert 'Traceback' not in err


def test_missing_and_non_mcap_files(tmp_path, capsys):
    assert replay_main([str(tmp_path / 'none.mcap')]) == 2
    assert 'cannot open' in capsys.readouterr().err
    assert replay_main([str(REPO / 'README.md')]) == 2
    assert 'not a readable MCAP file' in capsys.readouterr().err


def foreign_bag(path: Path, topic: str, encoding: str) -> Path:
    with path.open('wb') as f:
        w = Writer(f)
        w.start(profile='', library='test')
        schema = w.register_schema(name='Thing', encoding='jsonschema', data=b'{}')
        ch = w.register_channel(topic=topic, message_encoding=encoding, schema_id=schema)
        w.add_message(channel_id=ch, log_time=1, data=b'{"a": 1}', publish_time=1)
        w.finish()
    return path


def test_foreign_bags_give_clear_errors(tmp_path, capsys):
    bag = foreign_bag(tmp_path / 'json.mcap', '/other', 'json')
    assert replay_main([str(bag)]) == 2
    assert 'no /scan topic' in capsys.readouterr().err
    bag = foreign_bag(tmp_path / 'json2.mcap', '/scan', 'json')
    assert replay_main([str(bag)]) == 2
    assert '/scan is Thing, expected sensor_msgs/msg/LaserScan' in capsys.readouterr().err
    with pytest.raises(BagError, match='not a ROS 2 CDR channel'):
        list(read(bag))


def test_replay_through_the_real_node_agrees_with_in_process(capsys):
    bag = DATA / 'fig6d_big_wall.mcap'
    assert replay_main([str(bag), '--through-node', '--domain-id', '74',
                        '--tolerance', '1e-9']) == 0
    over_dds = capsys.readouterr().out
    assert replay_main([str(bag), '--tolerance', '1e-9']) == 0
    in_process = capsys.readouterr().out
    assert 'first divergence: none' in over_dds
    assert over_dds.split('\n')[0] == in_process.split('\n')[0]   # same count, none silent
