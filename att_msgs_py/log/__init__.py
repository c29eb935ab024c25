"""MCAP logs in rosbag2's layout: writing (:mod:`.writer`), reading (:mod:`.reader`), the recorder
node and ``att-replay``."""
from att_msgs_py.log.reader import TopicLog, iter_records, read_log
from att_msgs_py.log.writer import LogWriter

__all__ = ["LogWriter", "TopicLog", "iter_records", "read_log"]
