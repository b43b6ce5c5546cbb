"""core/ordered.InOrder: work on a pool of threads, results taken in the order handed in (what the
plane assistant relies on to find what one thread finds), errors raised at their turn."""
import threading
import unittest
from unittest import mock

from wiresculpt.core import ordered
from wiresculpt.core.ordered import InOrder


class TakenInOrder(unittest.TestCase):
    def test_a_later_piece_finishing_first_is_still_taken_second(self):
        first_may_end = threading.Event()
        second_ended = threading.Event()
        taken = []

        def first():
            # ends only after the second has ended: the two run at once, the second finishes first
            self.assertTrue(first_may_end.wait(30))
            return "first"

        def second():
            second_ended.set()
            first_may_end.set()
            return "second"

        with InOrder(lambda tag, result: taken.append((tag, result)), workers=2) as pool:
            pool.submit(1, first)
            pool.submit(2, second)
            self.assertTrue(second_ended.wait(30))
        self.assertEqual(taken, [(1, "first"), (2, "second")])

    def test_one_worker_runs_each_piece_on_the_callers_thread_before_submit_returns(self):
        taken, threads = [], set()

        def square(k):
            threads.add(threading.get_ident())
            return k * k

        with InOrder(lambda tag, result: taken.append(result), workers=1) as pool:
            for k in range(5):
                pool.submit(k, square, k)
                self.assertEqual(taken, [j * j for j in range(k + 1)])
        self.assertEqual(threads, {threading.get_ident()})

    def test_two_workers_keep_at_most_two_pending(self):
        taken = []
        with InOrder(lambda tag, result: taken.append(tag), workers=2) as pool:
            for k in range(7):
                pool.submit(k, lambda: None)
                self.assertLessEqual(len(pool.pending), 2)
                self.assertEqual(taken, list(range(len(taken))))
        self.assertEqual(taken, list(range(7)))

    def test_an_error_is_raised_at_its_turn_and_later_work_is_not_taken(self):
        taken = []

        def fail():
            raise KeyError("boom")

        with self.assertRaises(KeyError):
            with InOrder(lambda tag, result: taken.append(tag), workers=2) as pool:
                pool.submit(0, lambda: 0)
                pool.submit(1, fail)
                pool.submit(2, lambda: 2)
                pool.drain()
        self.assertEqual(taken, [0])


class Workers(unittest.TestCase):
    """Two at once (when asked for) only when the load average leaves a core idle."""

    def load(self, cores, load, most=2):
        with mock.patch("os.cpu_count", return_value=cores), mock.patch("os.getloadavg", return_value=(load, 0, 0)):
            return ordered.workers(most)

    def test_the_default_is_workers(self):
        self.assertEqual(self.load(8, 0.0, None), ordered.WORKERS)

    def test_a_spare_core_gives_two(self):
        self.assertEqual(self.load(2, 0.3), 2)
        self.assertEqual(self.load(2, 1.0), 2)
        self.assertEqual(self.load(8, 5.0), 2)  # never more than asked for

    def test_no_spare_core_gives_one(self):
        self.assertEqual(self.load(2, 1.2), 1)
        self.assertEqual(self.load(2, 10.0), 1)

    def test_no_load_average_gives_two(self):
        with mock.patch("os.getloadavg", side_effect=OSError):
            self.assertEqual(ordered.workers(2), 2)


if __name__ == "__main__":
    unittest.main()
