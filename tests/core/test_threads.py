import pytest
import torch

from motionlab.core import threads


def test_threads_for_small_work_is_one_thread():
    assert threads.threads_for(threads.SMALL_ROWS) == 1
    assert threads.threads_for(threads.SMALL_ROWS + 1) == torch.get_num_threads()
    with pytest.raises(ValueError, match="rows must be >= 0"):
        threads.threads_for(-1)


def test_batch_threads_one_on_the_cpu_unless_asked():
    assert threads.batch_threads("cpu") == 1
    assert threads.batch_threads(torch.device("cpu"), 3) == 3
    assert threads.batch_threads("meta") == torch.get_num_threads()
    with pytest.raises(ValueError, match="requested must be >= 1"):
        threads.batch_threads("cpu", 0)


def test_torch_threads_restores_the_count():
    before = torch.get_num_threads()
    with threads.torch_threads(1) as n:
        assert n == 1 and torch.get_num_threads() == 1
    assert torch.get_num_threads() == before
